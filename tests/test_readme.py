"""The README's Python examples run as written (in a scratch folder)."""

import re
from pathlib import Path

import matplotlib

README = Path(__file__).resolve().parents[1] / "README.md"


def _python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)


def test_readme_python_examples_run(tmp_path, monkeypatch, tiny_demo_toml):
    matplotlib.use("Agg")
    blocks = _python_blocks()
    assert len(blocks) == 2
    monkeypatch.chdir(tmp_path)
    tiny_demo_toml(tmp_path).rename(tmp_path / "my_study.toml")
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, str(README), "exec"), namespace)  # noqa: S102 - our own README
    assert (tmp_path / "run" / "result.json").exists()
    assert (tmp_path / "runs" / "my_study" / "report.html").exists()
    assert namespace["summary"]["name"] == "demo"
