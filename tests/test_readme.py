"""The README read in a minute (issue 36 item 5), and the documentation it points to kept current.

- the README is at most 150 lines and opens with the two commands for a fresh machine;
- its answer section's lines are short, and every number in them is one the recorded validate printout
  (docs/guides/claim.md) or the guide it moved to states: a re-rounded or invented number fails;
- every relative link of the README and of docs/ resolves to a file, and an anchor to a heading there;
- the commands reference names every built-in law and tracker of ``controllers.registry`` and every command;
- the API page's index, readable in the repository, lists exactly the entries the site renders;
- compare's recorded league table names the columns of today's table that it lacks;
- the README's Python block (a law of your own) runs.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.rglob("*.md"))
MAX_LINES = 150  # issue 36 item 5
MAX_ANSWER_LINE = 200  # characters, issue 36 item 5

FENCED = re.compile(r"^\s*```.*?^\s*```", re.MULTILINE | re.DOTALL)
INLINE_CODE = re.compile(r"`[^`\n]*`")
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$", re.MULTILINE)
NUMBER = re.compile(r"(?<![\w.])[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?(?![\w])")


def _section(text: str, heading: str) -> list[str]:
    """The lines of the ``## heading`` section, up to the next ``## ``."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("## ") and line[3:].startswith(heading))
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
    return lines[start:end]


# ----------------------------------------------------------------------------------------------- the README
def test_the_readme_is_at_most_150_lines():
    lines = README.read_text().splitlines()
    assert len(lines) <= MAX_LINES, f"README.md has {len(lines)} lines; at most {MAX_LINES}"


def test_the_readme_opens_with_the_two_commands():
    lines = README.read_text().splitlines()
    body = [line for line in lines if line.strip()]
    assert body[0].startswith("# "), "the title first"
    assert body[1].startswith("```"), f"the first thing after the title is a code block, not {body[1]!r}"
    close = body.index("```", 2)
    commands = [line.split("#")[0].strip() for line in body[2:close]]
    assert commands == ["make demo", "make test"], commands


def test_every_line_of_the_answer_is_short():
    answer = _section(README.read_text(), "The answer")
    long = [(len(line), line[:60]) for line in answer if len(line) >= MAX_ANSWER_LINE]
    assert not long, f"answer lines of {MAX_ANSWER_LINE} characters or more: {long}"


def test_the_answer_names_its_command_date_machine_and_figure():
    answer = "\n".join(_section(README.read_text(), "The answer"))
    for needed in ("make demo", "wmr-mj validate", "2026-11-26", "2-core", "docs/img/fig4_trajectory.png"):
        assert needed in answer, needed
    assert (ROOT / "docs" / "img" / "fig4_trajectory.png").is_file()


def test_every_number_of_the_answer_is_one_the_guide_records():
    """The answer quotes the validate printout kept in docs/guides/claim.md: each of its numbers appears there,
    written the same way (so none is re-rounded or made up in the README)."""
    answer = "\n".join(_section(README.read_text(), "The answer"))
    answer = LINK.sub("", answer)  # a link's target (docs/img/fig4...) is no number
    guide = (DOCS / "guides" / "claim.md").read_text()
    recorded = set(NUMBER.findall(guide))
    missing = sorted({n for n in NUMBER.findall(answer) if n not in recorded})
    assert not missing, f"numbers of the README's answer that docs/guides/claim.md does not state: {missing}"


@pytest.mark.slow
def test_the_readmes_python_blocks_run(tmp_path, monkeypatch):
    mktestdocs = pytest.importorskip("mktestdocs", reason="mktestdocs is not installed: pip install -e '.[docs]'")
    blocks = mktestdocs.grab_code_blocks(README.read_text(), lang="python")
    assert blocks, "the README shows a law of your own in a python block"
    monkeypatch.chdir(tmp_path)  # whatever a block writes stays out of the checkout
    mktestdocs.check_md_file(README, lang="python", memory=True)


# ------------------------------------------------------------------------------------------------- links
def _slug(heading: str) -> str:
    from markdown.extensions.toc import slugify  # type: ignore[import-untyped]  # what mkdocs' toc uses

    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link in a heading: its text
    return slugify(text.replace("`", "").replace("*", ""), "-")


def _anchors(page: Path) -> set[str]:
    return {_slug(h) for h in HEADING.findall(FENCED.sub("", page.read_text()))}


def _links(page: Path) -> list[str]:
    text = INLINE_CODE.sub("", FENCED.sub("", page.read_text()))
    return [t for t in LINK.findall(text) if not re.match(r"[a-z][a-z0-9+.-]*:", t)]  # relative ones only


@pytest.mark.parametrize("page", [README, *PAGES], ids=lambda p: str(p.relative_to(ROOT)))
def test_every_relative_link_resolves(page):
    pytest.importorskip("markdown", reason="markdown is not installed: pip install -e '.[docs]'")
    broken = []
    for target in _links(page):
        path_text, _, anchor = target.partition("#")
        path = (page.parent / path_text).resolve() if path_text else page
        if not path.exists():
            broken.append(f"{target}: no file {path.relative_to(ROOT) if path.is_relative_to(ROOT) else path}")
        elif anchor and path.suffix == ".md" and anchor not in _anchors(path):
            broken.append(f"{target}: no heading #{anchor} in {path.name}")
    assert not broken, f"{page.relative_to(ROOT)}: {broken}"


@pytest.mark.parametrize("page", [README, DOCS / "index.md"], ids=lambda p: str(p.relative_to(ROOT)))
def test_every_guide_and_reference_page_is_linked_from_the_front_pages(page):
    linked = {(page.parent / t.partition("#")[0]).resolve() for t in _links(page)}
    pages = sorted((*(DOCS / "guides").glob("*.md"), *(DOCS / "reference").glob("*.md")))
    missing = [str(p.relative_to(ROOT)) for p in pages if p.resolve() not in linked]
    assert not missing, f"{page.relative_to(ROOT)} links none of {missing}"


# ------------------------------------------------------------------------------------- the commands reference
def test_the_commands_reference_names_every_built_in_law_and_tracker():
    from controllers.registry import BUILTIN_TRACKERS, controller_names

    text = (DOCS / "reference" / "commands.md").read_text()
    missing = [n for n in (*controller_names(), *BUILTIN_TRACKERS) if f"`{n}`" not in text]
    assert not missing, f"docs/reference/commands.md does not name {missing}"
    for form in ("FILE.py:Class", "module:Class", "wmr_mj.controllers", "--controller-param", "--tracker-param"):
        assert form in text, form


def test_every_command_is_in_both_tables():
    from wmr_mj.cli.app import COMMANDS

    for page in (README, DOCS / "reference" / "commands.md"):
        named = set(re.findall(r"^\| `wmr-mj (\w+)", page.read_text(), re.MULTILINE))
        assert named == set(COMMANDS), f"{page.relative_to(ROOT)}: {sorted(set(COMMANDS) ^ named)}"


# ----------------------------------------------------------------------------------------------- the API page
def test_the_api_pages_index_lists_exactly_what_the_site_renders():
    text = (DOCS / "reference" / "api.md").read_text()
    rendered = re.findall(r"^::: (\S+)", text, re.MULTILINE)
    index = re.findall(r"^\| `([\w.]+)` \|", "\n".join(_section(text, "At a glance")), re.MULTILINE)
    assert index == rendered, (f"only in the index: {sorted(set(index) - set(rendered))}; "
                               f"only rendered: {sorted(set(rendered) - set(index))}")


# ------------------------------------------------------------------------------------- compare's recorded table
def test_the_recorded_league_table_names_the_columns_it_lacks():
    from wmr_mj.report.compare import COLUMNS

    record = _section((DOCS / "guides" / "compare.md").read_text(), "A record")
    header = next(line for line in record if line.startswith("| design |"))
    recorded = [c.strip() for c in header.strip("|").split("|")]
    today = [name for name, _ in COLUMNS]
    assert set(recorded) <= set(today), f"columns compare no longer prints: {set(recorded) - set(today)}"
    lacking = [c for c in today if c not in recorded]
    text = "\n".join(record)
    unnamed = [c for c in lacking if f"**{c}**" not in text]
    assert not unnamed, f"the record lacks {unnamed}, and compare.md does not say so"
