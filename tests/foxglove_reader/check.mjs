// Read a wmr-mj run log the way Foxglove does: @mcap/core's indexed reader (with @mcap/support's
// lz4/zstd decompressors), every ros2msg/cdr channel decoded by @foxglove/rosmsg2-serialization
// from the schema text in the file, json channels by JSON.parse. Prints one JSON object that
// tests/test_foxglove_reader.py compares with wmr_mj.logs.reader.load_log.
//
//   node tests/foxglove_reader/check.mjs LOG.mcap
import { open } from "node:fs/promises";

import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import { McapIndexedReader } from "@mcap/core";
import { FileHandleReadable } from "@mcap/nodejs";
import { loadDecompressHandlers } from "@mcap/support";

const path = process.argv[2];
if (!path) {
  console.error("usage: node check.mjs LOG.mcap");
  process.exit(2);
}
const handle = await open(path, "r");
const reader = await McapIndexedReader.Initialize({
  readable: new FileHandleReadable(handle),
  decompressHandlers: await loadDecompressHandlers(),
});

const text = new TextDecoder();
const decoders = new Map();
for (const [id, channel] of reader.channelsById) {
  const schema = reader.schemasById.get(channel.schemaId);
  if (channel.messageEncoding === "cdr" && schema?.encoding === "ros2msg") {
    const definitions = parse(text.decode(schema.data), { ros2: true });
    const messageReader = new MessageReader(definitions);
    decoders.set(id, (data) => messageReader.readMessage(data));
  } else if (channel.messageEncoding === "json") {
    decoders.set(id, (data) => JSON.parse(text.decode(data)));
  } else {
    throw new Error(`${channel.topic}: no decoder for ${channel.messageEncoding} / ${schema?.encoding}`);
  }
}

// Per topic: message count, log times, and the decoded values the test compares.
const topics = {};
const pick = (msg) => {
  const out = {};
  for (const [key, value] of Object.entries(msg)) {
    if (typeof value === "number") {
      out[key] = Number.isFinite(value) ? value : String(value);
    } else if (ArrayBuffer.isView(value)) {
      out[key] = { length: value.length, first: value[0], last: value[value.length - 1] };
    }
  }
  return out;
};
for await (const message of reader.readMessages()) {
  const channel = reader.channelsById.get(message.channelId);
  const decoded = decoders.get(message.channelId)(message.data);
  const entry = (topics[channel.topic] ??= { count: 0, first_log_time: String(message.logTime), messages: [] });
  entry.count += 1;
  entry.last_log_time = String(message.logTime);
  if (entry.messages.length < 3) {
    if (channel.topic === "/tf") {
      entry.messages.push(decoded.transforms.map((t) => ({
        parent: t.parent_frame_id, child: t.child_frame_id, sec: t.timestamp.sec, nsec: t.timestamp.nanosec,
        translation: [t.translation.x, t.translation.y, t.translation.z],
        rotation: [t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w],
      })));
    } else if (channel.topic === "/scene") {
      entry.messages.push({ entities: decoded.entities.map((e) => e.id) });
    } else {
      entry.messages.push(pick(decoded));
    }
  }
}
await handle.close();
console.log(JSON.stringify({
  library: reader.header.library,
  message_count: Number(reader.statistics?.messageCount ?? -1),
  topics,
}));
