"""`replay --verify` checks a plug-in's file before it imports it: a file changed since the run, or gone,
is refused (exit 2, one line naming the file and both SHA-256 prefixes) and never executed; a module
plug-in's file is found without running its package's ``__init__``; an unchanged file is said (on
stderr) and then imported; an entry point is found from its metadata, not loaded. And the replay's
verdict line carries its label once.

The plug-ins here write a marker file when imported: that marker is the witness of whether their code
ran. A run in this process leaves the plug-in's module in ``sys.modules`` (where a re-import would not
execute it again), so each check first removes it: the verification then imports as a fresh process
would, and the unchanged case shows the marker written by that import.
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest
from helpers import one_error_line

from controllers.registry import locate_source
from wmr_mj.cli.app import main
from wmr_mj.errors import ParameterError
from wmr_mj.logs.replay import _verdict_block, checked_plugins

LAW = '''
from pathlib import Path

from controllers import SteeringController

Path({marker!r}).write_text("imported")  # the side effect at import: the witness that this file ran


class MarkedPD(SteeringController):
    name = "marked-pd"

    def __init__(self, kp=50.0, kd=15.0):
        self.kp, self.kd = float(kp), float(kd)

    def voltage_scalar(self, alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot):
        return 0.385 * (alpha0_ddot + self.kd * (alpha0_dot - alpha_dot) + self.kp * (alpha0 - alpha))

    def describe(self):
        return {{"controller": self.name, "kp": self.kp, "kd": self.kd}}
'''
SHORT = ["--path", "lane-change", "--duration", "3"]  # a short run, as tests/test_loud_claims.py makes one


def _forget(*module_names: str, monkeypatch) -> None:
    """Drop modules a run in this process imported, so that the next import executes their files again."""
    for name in module_names:
        if name in sys.modules:
            monkeypatch.delitem(sys.modules, name)


def _file_module(path: Path) -> str:
    """The name controllers.registry imports a FILE.py plug-in under (its _from_file)."""
    return "wmr_mj_plugin_" + hashlib.sha256(str(path.resolve()).encode()).hexdigest()[:12]


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


# --------------------------------------------------------------------------- a file plug-in


@pytest.fixture(scope="module")
def file_run(tmp_path_factory):
    """A 3 s logged run (lane-change) of a FILE.py:Class plug-in that writes a marker when imported."""
    d = tmp_path_factory.mktemp("trust_file")
    marker = d / "imported.marker"
    law = d / "marked_law.py"
    text = LAW.format(marker=str(marker))
    law.write_text(text)
    log = d / "run.mcap"
    assert main(["run", "--controller", f"{law}:MarkedPD", *SHORT, "--out", str(log), "--json"]) == 0
    assert marker.exists()  # the run imported the plug-in: the marker works
    return {"law": law, "text": text, "marker": marker, "log": log, "sha": _sha(law)}


def test_an_unchanged_file_is_said_then_imported_and_verifies(file_run, capsys, monkeypatch):
    law, marker = file_run["law"], file_run["marker"]
    law.write_text(file_run["text"])
    _forget(_file_module(law), monkeypatch=monkeypatch)
    marker.unlink(missing_ok=True)
    assert main(["replay", str(file_run["log"]), "--verify"]) == 0
    out, err = capsys.readouterr()
    assert err.splitlines() == [f"replay: will import the controller plug-in 'marked-pd' from {law.resolve()}; its "
                                f"SHA-256 {file_run['sha'][:12]}... is the log's"]
    assert "controller 'marked-pd' re-run: the voltages it applied are bit-identical" in out
    assert marker.exists()  # the verification imported the file (so the checks below could have seen it run)


def test_a_changed_file_is_refused_before_it_runs(file_run, capsys, monkeypatch):
    law, marker = file_run["law"], file_run["marker"]
    law.write_text(file_run["text"] + "\n# changed since the run\n")
    _forget(_file_module(law), monkeypatch=monkeypatch)
    marker.unlink(missing_ok=True)
    assert main(["replay", str(file_run["log"]), "--verify"]) == 2
    line = one_error_line(capsys)
    assert str(law.resolve()) in line and "has changed since it ran" in line
    assert f"the record's {file_run['sha'][:12]}..." in line and f"SHA-256 is {_sha(law)[:12]}..." in line
    assert not marker.exists()  # never executed
    law.write_text(file_run["text"])


def test_a_deleted_file_is_refused(file_run, capsys, monkeypatch):
    law, marker = file_run["law"], file_run["marker"]
    law.unlink(missing_ok=True)
    _forget(_file_module(law), monkeypatch=monkeypatch)
    marker.unlink(missing_ok=True)
    try:
        assert main(["replay", str(file_run["log"]), "--verify"]) == 2
        line = one_error_line(capsys)
        assert str(law.resolve()) in line and "is gone" in line
        assert f"the record's SHA-256 {file_run['sha'][:12]}..., found: no file" in line
        assert not marker.exists()
    finally:
        law.write_text(file_run["text"])


def test_plain_replay_imports_nothing(file_run, capsys, monkeypatch):
    law, marker = file_run["law"], file_run["marker"]
    law.write_text(file_run["text"] + "\n# changed\n")  # would be refused by --verify; nothing else reads it
    _forget(_file_module(law), monkeypatch=monkeypatch)
    marker.unlink(missing_ok=True)
    try:
        assert main(["replay", str(file_run["log"]), "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["config"]["controller_plugin"]["name"] == "marked-pd"
        assert not marker.exists()
    finally:
        law.write_text(file_run["text"])


# --------------------------------------------------------------------------- a module plug-in in a package


@pytest.fixture()
def package(tmp_path, monkeypatch):
    """markpkg (its __init__ writes a marker) with markpkg/law.py (writes another) on sys.path."""
    root = tmp_path / "site"
    pkg = root / "markpkg"
    pkg.mkdir(parents=True)
    init_marker, law_marker = tmp_path / "init.marker", tmp_path / "law.marker"
    (pkg / "__init__.py").write_text(f"from pathlib import Path\nPath({str(init_marker)!r}).write_text('ran')\n")
    (pkg / "law.py").write_text(LAW.format(marker=str(law_marker)))
    monkeypatch.syspath_prepend(str(root))
    _forget("markpkg", "markpkg.law", monkeypatch=monkeypatch)
    return {"root": root, "pkg": pkg, "init_marker": init_marker, "law_marker": law_marker}


def test_a_module_is_located_without_running_its_package(package, monkeypatch):
    found = locate_source("markpkg.law:MarkedPD")
    assert found.path == package["pkg"] / "law.py" and found.module == "markpkg.law"
    assert found.runs_first == (package["pkg"] / "__init__.py",) and found.sha256 == _sha(package["pkg"] / "law.py")
    assert not package["init_marker"].exists() and not package["law_marker"].exists()
    assert "markpkg" not in sys.modules
    # the witness can fire: importlib's own find_spec runs the package's __init__ on the way
    importlib.util.find_spec("markpkg.law")
    assert package["init_marker"].exists() and not package["law_marker"].exists()
    _forget("markpkg", "markpkg.law", monkeypatch=monkeypatch)


def test_a_changed_module_plug_in_is_refused_before_its_package_runs(package, tmp_path, capsys, monkeypatch):
    log = tmp_path / "module.mcap"
    assert main(["run", "--controller", "markpkg.law:MarkedPD", *SHORT, "--out", str(log), "--json"]) == 0
    capsys.readouterr()
    law = package["pkg"] / "law.py"
    recorded = _sha(law)
    law.write_text(law.read_text() + "\n# changed since the run\n")
    _forget("markpkg", "markpkg.law", monkeypatch=monkeypatch)
    package["init_marker"].unlink()
    package["law_marker"].unlink()
    assert main(["replay", str(log), "--verify"]) == 2
    line = one_error_line(capsys)
    assert str(law) in line and f"the record's {recorded[:12]}..." in line and f"{_sha(law)[:12]}..." in line
    assert not package["init_marker"].exists() and not package["law_marker"].exists()
    # restored: said (with the __init__ that runs first), imported, verified
    law.write_text(law.read_text().replace("\n# changed since the run\n", ""))
    assert _sha(law) == recorded
    assert main(["replay", str(log), "--verify"]) == 0
    err = capsys.readouterr().err
    assert err.splitlines() == [f"replay: will import the controller plug-in 'marked-pd' from {law} (module "
                                f"markpkg.law); import runs first {package['pkg'] / '__init__.py'}; its SHA-256 "
                                f"{recorded[:12]}... is the log's"]
    assert package["init_marker"].exists() and package["law_marker"].exists()


def test_an_entry_point_is_located_from_its_metadata_without_loading_it(package):
    dist = package["root"] / "markplug-0.1.dist-info"  # an installed distribution, as pip leaves it
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: markplug\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[wmr_mj.controllers]\nmarked = markpkg.law:MarkedPD\n")
    found = locate_source("marked")
    assert found.form == "entry-point" and found.module == "markpkg.law" and found.path == package["pkg"] / "law.py"
    assert found.runs_first == (package["pkg"] / "__init__.py",)
    assert not package["init_marker"].exists() and not package["law_marker"].exists()


def test_a_module_that_cannot_be_found_without_running_code_is_refused(package):
    with pytest.raises(ParameterError, match="'markpkg.nowhere' is not found on sys.path, by a search that runs no"):
        locate_source("markpkg.nowhere:Law")
    assert not package["init_marker"].exists()


# --------------------------------------------------------------------------- a log from someone else


def test_a_plug_in_named_without_its_record_is_not_imported(tmp_path):
    marker = tmp_path / "imported.marker"
    law = tmp_path / "law.py"
    law.write_text(LAW.format(marker=str(marker)))
    log = SimpleNamespace(path=tmp_path / "other.mcap", config={"controller": f"{law}:MarkedPD"})
    with pytest.raises(ParameterError, match="holds no record of its source"):
        checked_plugins(log)
    record = {"spec": f"{law}:MarkedPD", "name": "marked-pd", "origin": "file", "import_path": f"{law}:MarkedPD",
              "params": {}, "source_sha256": None}
    log.config = {"controller": "marked-pd", "controller_plugin": record}
    with pytest.raises(ParameterError, match="has no SHA-256 in the log's record"):
        checked_plugins(log)
    assert not marker.exists()
    record["source_sha256"] = _sha(law)  # as recorded: checked, to be imported
    [checked] = checked_plugins(log)
    assert checked.kind == "controller" and checked.source.path == law and not marker.exists()


# --------------------------------------------------------------------------- the verdict's label


def test_the_verdict_line_is_labelled_once():
    lines = _verdict_block(["verdict: CERTIFIED-INSIDE  (tightness sup|E|/E_max = 0.500)",
                            "certificate:   |E| <= 0.01 rad", "drift: final alpha' = 0 rad/s"])
    assert lines == ["verdict    CERTIFIED-INSIDE  (tightness sup|E|/E_max = 0.500)",
                     "           certificate:   |E| <= 0.01 rad",
                     "           drift: final alpha' = 0 rad/s"]
    banner = "!!! CERTIFIED-OUTSIDE: every assumption of the certificate holds and the run is OUTSIDE it."
    assert _verdict_block([banner, "verdict: CERTIFIED-OUTSIDE"]) == [banner, "verdict    CERTIFIED-OUTSIDE"]


def test_replay_prints_the_verdict_under_one_label(file_run, capsys):
    assert main(["replay", str(file_run["log"])]) == 0
    out = capsys.readouterr().out
    assert "verdict    verdict" not in out
    verdict_lines = [x for x in out.splitlines() if x.startswith("verdict ")]
    assert verdict_lines == ["verdict    NO-CLAIM -- not a pass: controller 'marked-pd' states no claim; the run is "
                             "judged by its requirements only (--require)"]
