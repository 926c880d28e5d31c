"""The documentation site (docs/, mkdocs.yml): it builds with ``mkdocs build --strict`` and its code blocks run.

Every fenced block of a page names its language, and the language says what this test does with it
(mktestdocs collects the blocks of one language):

- ``python``: run, the blocks of one page in order in one namespace (mktestdocs ``memory=True``),
  in a temporary working folder;
- ``sh``: run by bash (``-e -u``), ``wmr-mj`` being this checkout's command line
  (``python -m wmr_mj.cli``), in a temporary working folder; only cheap commands belong here;
- ``toml``: a route file (the format of ``wmr_mj/reference/route.py``), parsed into a route;
- ``console``: a transcript (``$ command`` and its output) shown, not run: long commands and their
  recorded output.
"""

from __future__ import annotations

import importlib.util
import os
import re
import shlex
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

mktestdocs = pytest.importorskip("mktestdocs", reason="mktestdocs is not installed: pip install -e '.[docs]'")

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.rglob("*.md"))
LANGUAGES = ("python", "sh", "toml", "console")
FENCE = re.compile(r"^\s*```(\S*)", re.MULTILINE)


def _ids(pages):
    return [str(p.relative_to(DOCS)) for p in pages]


def _env() -> dict[str, str]:
    env = dict(os.environ, MPLBACKEND="Agg", NO_MKDOCS_2_WARNING="1")
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
    return env


def _blocks(page: Path, lang: str) -> list[str]:
    return mktestdocs.grab_code_blocks(page.read_text(), lang=lang)


def test_the_site_builds_strict(tmp_path):
    """Warnings are errors: a broken link, a missing page, an API entry mkdocstrings cannot load."""
    missing = [m for m in ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers.python")
               if importlib.util.find_spec(m) is None]
    if missing:
        pytest.skip(f"{', '.join(missing)} not importable: pip install -e '.[docs]' (make venv installs it)")
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file",
                           str(ROOT / "mkdocs.yml"), "--site-dir", str(tmp_path / "site")],
                          cwd=ROOT, env=_env(), capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert (tmp_path / "site" / "reference" / "api" / "index.html").is_file()
    api = (tmp_path / "site" / "reference" / "api" / "index.html").read_text()
    for name in ("wmr_mj.sim.config.RunConfig", "wmr_mj.sim.closed_loop.run_closed_loop", "wmr_mj.sim.batch.run_batch",
                 "wmr_mj.experiments.sweep.run_sweep", "wmr_mj.sim.certify.certificate_for",
                 "wmr_mj.searches.falsify.falsify", "wmr_mj.logs.reader.load_log", "wmr_mj.logs.replay", "controllers"):
        assert f'id="{name}"' in api, name


@pytest.mark.parametrize("page", PAGES, ids=_ids(PAGES))
def test_every_block_names_a_language_this_test_knows(page):
    text = page.read_text()
    opening = FENCE.findall(text)[::2]  # fences alternate: opening, closing
    assert len(FENCE.findall(text)) % 2 == 0, f"{page}: an unclosed code block"
    unknown = [lang or "(none)" for lang in opening if lang not in LANGUAGES]
    assert not unknown, f"{page}: code blocks in {unknown}; use one of {LANGUAGES}"


PYTHON_PAGES = [p for p in PAGES if _blocks(p, "python")]
SH_PAGES = [p for p in PAGES if _blocks(p, "sh")]
TOML_PAGES = [p for p in PAGES if _blocks(p, "toml")]


@pytest.mark.slow
@pytest.mark.parametrize("page", PYTHON_PAGES, ids=_ids(PYTHON_PAGES))
def test_python_blocks_run(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # whatever a block writes stays out of the checkout
    mktestdocs.check_md_file(page, lang="python", memory=True)


@pytest.mark.slow
@pytest.mark.parametrize("page", SH_PAGES, ids=_ids(SH_PAGES))
def test_sh_blocks_run(page, tmp_path):
    prelude = f'wmr-mj() {{ {shlex.quote(sys.executable)} -m wmr_mj.cli "$@"; }}\n'
    for block in _blocks(page, "sh"):
        proc = subprocess.run(["bash", "-e", "-u", "-c", prelude + block], cwd=tmp_path, env=_env(),
                              capture_output=True, text=True, timeout=120)
        assert proc.returncode == 0, f"{page}:\n{block}\n{proc.stdout[-3000:]}{proc.stderr[-3000:]}"


@pytest.mark.parametrize("page", TOML_PAGES, ids=_ids(TOML_PAGES))
def test_toml_blocks_are_routes(page):
    from wmr_mj.reference.route import parse_route

    for block in _blocks(page, "toml"):
        route = parse_route(tomllib.loads(block), f"{page.name} block")
        assert route.path.length > 0
