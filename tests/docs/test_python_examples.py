"""The Python examples of the docs (docs/how-to/python.md) run as written, in a scratch folder."""

import re
from pathlib import Path

import matplotlib

PAGE = Path(__file__).resolve().parents[2] / "docs" / "how-to" / "python.md"
# The study the page runs (``my_study.toml``, not shown on the page): the tiny demo with the optional
# stages off and one family, target and task. Every stage of the tiny demo, as a study runs it, is
# checked on the session's ``tiny_run`` (tests/experiment, tests/report); here, that the page's
# call runs a study to its report.
SMALL_STUDY = {
    "synth.methods": "[]",
    "train.families": '["par"]',
    "importance.targets": '["E"]',
    "optimize.tasks": "1",
    "bench.tasks": "0",
    "identify.enabled": "false",
}


def _python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", PAGE.read_text(encoding="utf-8"), flags=re.S)


def test_python_examples_run(tmp_path, monkeypatch, tiny_demo_toml):
    matplotlib.use("Agg")
    blocks = _python_blocks()
    assert len(blocks) == 2
    monkeypatch.chdir(tmp_path)
    tiny_demo_toml(tmp_path, **SMALL_STUDY).rename(tmp_path / "my_study.toml")
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, str(PAGE), "exec"), namespace)  # noqa: S102 - our own docs page
    assert (tmp_path / "run" / "result.json").exists()
    assert (tmp_path / "runs" / "my_study" / "report.html").exists()
    assert namespace["summary"]["name"] == "demo"
    assert namespace["summary"]["tasks"] == 1
