"""Bad output paths and absurd sizes: one line on stderr, exit status 2, no traceback, nothing left behind."""

from __future__ import annotations

import errno
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import files_under, one_error_line

from wmr_mj._util.files import check_output_path
from wmr_mj.cli.app import main
from wmr_mj.errors import NotEnoughMemoryError, OutputPathError

REPO = Path(__file__).resolve().parents[1]


# a regular file where a folder is needed: fails for root too (permissions would not)
@pytest.mark.parametrize("argv", [
    ["run", "--duration", "10", "--out", "{blocker}/run.mcap"],
    ["identify", "--duration", "1", "--out", "{blocker}/sub/identified.json"],
    ["sweep", "--n", "1", "--duration", "10", "--out", "{blocker}"],
    ["validate", "--n", "1", "--out", "{blocker}/report"],
    ["figures", "--duration", "10", "--out", "{blocker}/figures"],
], ids=lambda argv: argv[0])
def test_unwritable_output_path_is_one_line(tmp_path, capsys, argv):
    blocker = tmp_path / "a-file"
    blocker.write_text("in the way\n")
    before = files_under(tmp_path)
    code = main([a.format(blocker=blocker) for a in argv])
    line = one_error_line(capsys)
    assert code == 2
    assert "--out" in line and str(blocker) in line and "not a folder" in line, line
    assert files_under(tmp_path) == before  # no partial file or folder
    assert blocker.read_text() == "in the way\n"


def test_output_path_that_is_a_folder(tmp_path, capsys):
    assert main(["identify", "--duration", "1", "--out", str(tmp_path)]) == 2
    assert "is a folder" in one_error_line(capsys)
    assert files_under(tmp_path) == []


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux /proc (a folder no one can write)")
def test_folder_that_cannot_be_created(capsys):
    assert main(["run", "--duration", "10", "--out", "/proc/wmr-mj-test/run.mcap"]) == 2
    line = one_error_line(capsys)
    assert "cannot create the folder /proc/wmr-mj-test" in line, line
    assert not Path("/proc/wmr-mj-test").exists()


def test_check_output_path_accepts_new_folders_and_leaves_nothing(tmp_path):
    assert check_output_path(tmp_path / "a" / "b" / "run.mcap", kind="file") == tmp_path / "a" / "b" / "run.mcap"
    assert check_output_path(tmp_path / "c" / "d", kind="dir") == tmp_path / "c" / "d"
    (tmp_path / "e").mkdir()
    assert check_output_path(tmp_path / "e", kind="dir") == tmp_path / "e"  # an existing folder resumes
    assert files_under(tmp_path) == ["e"]  # no probe, no folder made by the check


def test_check_output_path_removes_the_folders_it_made_on_failure(tmp_path, monkeypatch):
    import tempfile

    def full_disk(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(tempfile, "mkstemp", full_disk)
    with pytest.raises(OutputPathError, match=r"--out .*cannot create a file in .*No space left on device"):
        check_output_path(tmp_path / "new" / "deeper" / "x.json", kind="file", option="--out")
    assert files_under(tmp_path) == []


def test_huge_run_is_refused_up_front():
    """--duration 1e9 would allocate ~1e12 rows: refused at once with the size, no allocation attempted."""
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "run", "--duration", "1e9", "--no-log"],
                          capture_output=True, text=True, timeout=60, cwd=REPO)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert "1e+12 control steps" in lines[0] and "TiB of memory" in lines[0] and "available" in lines[0], lines[0]
    assert proc.stdout == ""


def test_library_refuses_a_run_that_does_not_fit(monkeypatch):
    """run_closed_loop itself refuses (not only the command): with 1 MiB available a 10 s run
    (10,000 rows of 320 bytes = 3.05 MiB) does not fit."""
    from wmr_mj._util import memory
    from wmr_mj.sim.closed_loop import run_closed_loop
    from wmr_mj.sim.config import RunConfig

    monkeypatch.setattr(memory, "available_memory_bytes", lambda: 1 << 20)
    with pytest.raises(NotEnoughMemoryError, match=r"1e\+04 control steps.*3\.05 MiB of memory, 1 MiB is available"):
        run_closed_loop(RunConfig(duration=10.0), progress=False)


def test_require_memory_compares_with_what_is_available(monkeypatch):
    from wmr_mj._util import memory

    monkeypatch.setattr(memory, "available_memory_bytes", lambda: 4 << 30)
    memory.require_memory(4 << 30, what="a job")  # exactly what is there: accepted
    with pytest.raises(NotEnoughMemoryError, match=r"a job would need about 4 GiB of memory, 4 GiB is available"):
        memory.require_memory((4 << 30) + (1 << 20), what="a job")
    monkeypatch.setattr(memory, "available_memory_bytes", lambda: None)
    memory.require_memory(1e30, what="a job")  # unknown: not refused


def test_available_memory_is_plausible():
    available = __import__("wmr_mj._util.memory", fromlist=["x"]).available_memory_bytes()
    assert available is None or 16 << 20 < available < 1 << 50


def test_bad_input_after_a_good_output_path_leaves_nothing(tmp_path, capsys):
    assert main(["sweep", "--n", "1", "--path", "no-such-path", "--out", str(tmp_path / "new" / "sweep")]) == 2
    assert "no-such-path" in one_error_line(capsys)
    assert files_under(tmp_path) == []


def test_a_gl_backend_that_cannot_load_is_one_line():
    """MUJOCO_GL naming a backend whose library is missing breaks `import mujoco` itself."""
    import os
    import subprocess
    import sys

    env = {**os.environ, "MUJOCO_GL": "osmesa"}
    probe = subprocess.run([sys.executable, "-c", "import mujoco"], env=env, capture_output=True, text=True)
    if probe.returncode == 0:
        pytest.skip("OSMesa is installed here: MUJOCO_GL=osmesa imports fine")
    proc = subprocess.run([sys.executable, "-m", "wmr_mj.cli", "run", "--no-log"], env=env, capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "MUJOCO_GL='osmesa'" in lines[0] and "Traceback" not in proc.stderr


@pytest.mark.parametrize("argv, names", [
    (["run", "--no-log", "--reference-bounds", "alpha_dot=0.2"], "alpha_dot_max"),
    (["run", "--no-log", "--reference-bounds", "alpha_dot_max=fast"], "alpha_dot_max"),
    (["falsify", "--path-knots", "-1", "--budget", "8"], "--path-knots"),
    (["falsify", "--budget", "8", "--disturbance", "kind=step,amplitude=1", "--range", "disturbance.width=0:1"],
     "amplitude, t1"),
    (["falsify", "--budget", "8", "--range", "disturbance.amplitude=-1:1"], "no disturbance"),
    (["falsify", "--budget", "8", "--disturbance", "kind=step,amplitude=1", "--range", "load0.m1=600:700"],
     "0 load change"),
    (["sweep", "--n", "1", "--require", "always(abs(Q) <= 1)"], "valid signals"),
], ids=["bounds-key", "bounds-value", "knots", "signal-field", "no-disturbance", "no-load", "sweep-require"])
def test_bad_search_spaces_and_bounds_are_one_line_exit_2(tmp_path, capsys, argv, names):
    code = main([*argv, "--duration", "10", *(["--out", str(tmp_path / "o")] if argv[0] != "run" else [])])
    line = one_error_line(capsys)
    assert code == 2 and names in line, line
