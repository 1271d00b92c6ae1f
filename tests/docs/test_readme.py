"""The README is the front door: short, opening with the two commands, free of run-specific ids,
and every file it links exists. (Its command lines are checked against the command-line app with
the docs' in ``test_site.py``; the content it used to hold lives in ``docs/``.)"""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"


def _text() -> str:
    return README.read_text(encoding="utf-8")


def test_readme_is_short_and_opens_with_the_two_commands():
    lines = _text().splitlines()
    assert len(lines) <= 160, f"README.md has {len(lines)} lines; the front door keeps to about 150"
    head = "\n".join(lines[:15])
    assert "make demo" in head and "make test" in head, (
        "the README must open with `make demo` and `make test`"
    )


def test_readme_names_no_task_issue_or_finding():
    text = _text()
    ids = re.findall(r"(?<![-\w])(?:task|issue)s?\s*#?\s*\d+|#\d+\b|\bfindings?\b", text, flags=re.I)
    assert not ids, f"run-specific ids in README.md (move them to docs/ or BENCHMARKS.md): {ids}"


def test_readme_links_exist():
    links = re.findall(r"\]\(([^)\s]+)\)", _text())
    local = [link.split("#")[0] for link in links if not re.match(r"[a-z]+://", link)]
    assert "docs/assets/power-plan.png" in local, "the README's picture"
    for link in local:
        assert (ROOT / link).exists(), f"README.md links {link}, which does not exist"
