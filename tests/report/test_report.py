"""report.html: every section and thesis item is there, it is self-contained, and it renders."""

import json
import os
import shutil
import subprocess
import tempfile
from html.parser import HTMLParser
from pathlib import Path

import pandas as pd
import pytest

from joulepath.report import THESIS_ITEMS, render_report, verdicts
from joulepath.report._html import SECTIONS


class _Collect(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.sections: list[str] = []
        self.thesis: list[str] = []
        self.hypotheses: list[str] = []
        self.images: list[str] = []
        self.scripts = 0
        self.links: list[str] = []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "section":
            self.sections.append(a["id"])
        if "data-thesis" in a:
            self.thesis.append(a["data-thesis"])
        if "data-hypothesis" in a:
            self.hypotheses.append(a["data-hypothesis"])
        if tag == "img":
            self.images.append(a["src"])
        if tag == "script":
            self.scripts += 1
        for key in ("href", "src"):
            if key in a and not a[key].startswith(("#", "data:")):
                self.links.append(a[key])


def _parse(path: Path) -> _Collect:
    parser = _Collect()
    parser.feed(path.read_text(encoding="utf-8"))
    return parser


def test_report_has_every_section_thesis_item_and_hypothesis(tiny_run):
    page = _parse(tiny_run / "report.html")
    assert page.sections == [sid for sid, _ in SECTIONS]
    assert set(page.thesis) == {item.key for item in THESIS_ITEMS}
    assert page.hypotheses == ["H1", "H2", "H3"]
    assert len(page.images) >= 15 and all(src.startswith("data:image/png;base64,") for src in page.images)
    assert page.scripts == 0 and page.links == [], "the report must be self-contained"
    text = (tiny_run / "report.html").read_text(encoding="utf-8")
    for honest in ("vs_default_mean", "cv_grouped_r2", "cv_shuffled_r2", "saved_lab_pct"):
        assert honest in text


def test_report_without_optional_stages_says_what_was_not_run(tiny_run, tmp_path):
    run = tmp_path / "run"
    shutil.copytree(tiny_run, run)
    shutil.rmtree(run / "synth")
    shutil.rmtree(run / "bench")
    page = _parse(render_report(run))
    assert page.sections == [sid for sid, _ in SECTIONS]
    assert set(page.thesis) == {item.key for item in THESIS_ITEMS}
    text = (run / "report.html").read_text(encoding="utf-8")
    assert "Synthesis was not run in this experiment" in text
    assert "The optimizer benchmark was not run" in text
    found = {v.key: v.verdict for v in verdicts(run)}
    assert found["H2"] == "not tested" and found["H3"] == "not tested" and found["H1"] != "not tested"


def _bench_run(tmp_path: Path, ma: float, ga: float, std: float, tasks: int) -> Path:
    (tmp_path / "bench").mkdir(parents=True)
    (tmp_path / "summary.json").write_text(json.dumps({"experiment": {"bench": {"tasks": tasks}}}))
    pd.DataFrame(
        [
            {
                "configuration": "GA random",
                "vs_initial_mean": 30.0,
                "vs_initial_std": 1.0,
                "vs_default_mean": ga,
                "vs_default_std": std,
            },
            {
                "configuration": "MA informed local search",
                "vs_initial_mean": 35.0,
                "vs_initial_std": 1.0,
                "vs_default_mean": ma,
                "vs_default_std": std,
            },
        ]
    ).to_csv(tmp_path / "bench" / "table.csv", index=False)
    return tmp_path


@pytest.mark.parametrize(
    ("ma", "ga", "std", "tasks", "expected"),
    [
        (8.0, 5.0, 2.0, 100, "supported"),  # 3 points ahead, standard error 0.28
        (5.5, 5.0, 2.0, 4, "partly supported"),  # ahead by less than two standard errors
        (4.0, 5.0, 2.0, 100, "not supported"),
    ],
)
def test_h3_verdict_weighs_the_difference_against_its_standard_error(tmp_path, ma, ga, std, tasks, expected):
    run = _bench_run(tmp_path, ma, ga, std, tasks)
    h3 = verdicts(run)[2]
    assert h3.key == "H3" and h3.verdict == expected
    assert f"{ma:.1f} %" in h3.evidence and "thesis' metric" in h3.evidence


CHECK = """<script>
window.addEventListener('load', () => {
  const out = {sections: [], images: [], width: document.documentElement.scrollWidth};
  for (const s of document.querySelectorAll('section')) {
    const r = s.getBoundingClientRect();
    out.sections.push({id: s.id, height: r.height, text: s.innerText.trim().length});
  }
  for (const img of document.images) {
    out.images.push({alt: img.alt, complete: img.complete, natural: img.naturalWidth,
                     shown: img.getBoundingClientRect().width});
  }
  const pre = document.createElement('pre');
  pre.id = 'render-check';
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
});
</script>"""


def _chromium() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        found = shutil.which(name)
        if found:
            return found
    return None


def test_report_renders_in_headless_chromium(tiny_run, tmp_path):
    browser = _chromium()
    if browser is None:
        if os.environ.get("JOULEPATH_REQUIRE_BROWSER"):
            pytest.fail("JOULEPATH_REQUIRE_BROWSER is set but no chromium is installed")
        pytest.skip("no headless Chromium (Debian: apt-get install chromium)")
    page = tmp_path / "report.html"
    page.write_text(
        (tiny_run / "report.html").read_text(encoding="utf-8").replace("</body>", CHECK + "</body>"),
        encoding="utf-8",
    )
    with tempfile.TemporaryDirectory() as profile:
        done = subprocess.run(
            [
                browser,
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                f"--user-data-dir={profile}",
                "--window-size=1280,900",
                "--virtual-time-budget=10000",
                "--dump-dom",
                page.as_uri(),
            ],
            capture_output=True,
            text=True,
            timeout=180,
            check=False,
        )
    assert done.returncode == 0, done.stderr[-2000:]
    start = done.stdout.index('<pre id="render-check">') + len('<pre id="render-check">')
    result = json.loads(done.stdout[start : done.stdout.index("</pre>", start)].replace("&quot;", '"'))
    assert [s["id"] for s in result["sections"]] == [sid for sid, _ in SECTIONS]
    for section in result["sections"]:
        assert section["height"] > 50 and section["text"] > 40, section
    assert len(result["images"]) == len(_parse(tiny_run / "report.html").images)
    for image in result["images"]:
        assert image["complete"] and image["natural"] > 100 and image["shown"] > 100, image
    assert result["width"] <= 1280, "the page scrolls sideways"


def test_h3_verdict_pairs_the_configurations_task_by_task(tmp_path):
    run = _bench_run(tmp_path, 6.0, 5.0, 4.0, 6)  # unpaired: 1 point ahead, standard error 2.3
    noise = [3.0, -4.0, 8.0, 0.0, -2.0, 7.0]  # task difficulty, shared by both configurations
    rows = [
        {"configuration": name, "task": k, "vs_default": base + gain + 0.05 * (-1) ** k}
        for k, base in enumerate(noise)
        for name, gain in (("GA random", 5.0), ("MA informed local search", 6.0))
    ]
    pd.DataFrame(rows).to_csv(run / "bench" / "runs.csv", index=False)
    h3 = verdicts(run)[2]
    assert h3.verdict == "supported" and "MA better on 6 of 6 tasks" in h3.evidence


def test_h3_verdict_leaves_out_joulepaths_own_default(tmp_path):
    """H3 compares the thesis' MA with its GA/DE; a better default search must not stand in for the GA."""
    run = _bench_run(tmp_path, 8.0, 5.0, 2.0, 100)
    table = pd.read_csv(run / "bench" / "table.csv")
    default = {
        "configuration": "joulepath default (gradient)",
        "vs_initial_mean": float("nan"),
        "vs_initial_std": float("nan"),
        "vs_default_mean": 20.0,
        "vs_default_std": 2.0,
    }
    pd.concat([pd.DataFrame([default]), table]).to_csv(run / "bench" / "table.csv", index=False)
    h3 = verdicts(run)[2]
    assert h3.verdict == "supported" and "joulepath default" not in h3.evidence
