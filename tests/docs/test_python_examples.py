"""The Python examples of the docs (docs/how-to/python.md) run as written, in a scratch folder."""

import re
from pathlib import Path

import matplotlib

PAGE = Path(__file__).resolve().parents[2] / "docs" / "how-to" / "python.md"


def _python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", PAGE.read_text(encoding="utf-8"), flags=re.S)


def test_python_examples_run(tmp_path, monkeypatch, tiny_demo_toml):
    matplotlib.use("Agg")
    blocks = _python_blocks()
    assert len(blocks) == 2
    monkeypatch.chdir(tmp_path)
    tiny_demo_toml(tmp_path).rename(tmp_path / "my_study.toml")
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, str(PAGE), "exec"), namespace)  # noqa: S102 - our own docs page
    assert (tmp_path / "run" / "result.json").exists()
    assert (tmp_path / "runs" / "my_study" / "report.html").exists()
    assert namespace["summary"]["name"] == "demo"
