"""A plant run: its report, its cache, resumed after kill -9 of the client, on a real scheduler (a worker
killed mid-task)."""

from __future__ import annotations

import csv
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from joulepath.plant import read_plant, run_plant, write_plant_report
from joulepath.plant._run import CACHE, RESULT, plan_tasks

from .conftest import CELLS, cell_results


def test_plant_run_writes_the_report(reference_run):
    summary = json.loads((reference_run / "plant.json").read_text())
    cells = {c["cell"]: c for c in summary["cells"]}
    assert summary["n_cells"] == 4 and summary["n_failed"] == 0
    assert cells["task"]["status"] == "ok"  # two modules, its tool in the system module, an I/O scenario
    for name in CELLS:
        c = cells[name]
        assert c["status"] in ("ok", "refused"), c
        assert c["measure"] == "electrical" and c["written"] in ("rapid", "egm", None)
        assert 0 <= c["optimized_J_per_cycle"] <= c["default_J_per_cycle"]
        split = c["split_default"]
        assert split["motion_J"] + split["holding_J"] + split["standby_J"] == pytest.approx(
            c["default_J_per_cycle"], rel=1e-3
        )
        waits = sum(CELLS[name][1:])
        assert waits <= split["standstill_s"] < c["default_cycle_s"]  # waits and stops stand still
        assert c["cycles_per_year"] == pytest.approx(6000 * 3600 / c["default_cycle_s"])
        assert c["saved_EUR_per_year"] == pytest.approx(0.2 * c["saved_kWh_per_year"])
        assert (reference_run / "cells" / name / "cycle.json").is_file()
    # beta waits 2 s: long enough for the brakes; alpha's 1.2 s too, gamma's 0.8 s twice: every cell saves
    assert all(cells[n]["idle_modes_kWh_per_year"] > 0 for n in CELLS)
    t = summary["totals"]
    every = [*CELLS, "task"]
    assert t["default_kWh_per_year"] == pytest.approx(sum(cells[n]["default_kWh_per_year"] for n in every))
    assert t["saved_kWh_per_year"] == pytest.approx(sum(cells[n]["saved_kWh_per_year"] for n in every))
    shares = t["motion_share_pct"] + t["holding_share_pct"] + t["standby_share_pct"]
    assert shares == pytest.approx(100.0, rel=1e-3)
    ranked = [cells[n]["saved_kWh_per_year"] for n in summary["ranking"]]
    assert ranked == sorted(ranked, reverse=True)
    rows = list(csv.DictReader((reference_run / "cells.csv").read_text().splitlines()))
    assert [r["cell"] for r in rows] == ["alpha", "beta", "gamma", "task"]
    html = (reference_run / "report.html").read_text()
    assert all(f'<section id="{s}">' in html for s in ("summary", "ranking", "energy", "programs"))


def test_plant_rerun_computes_only_what_is_missing(mini_plant, reference_run, tmp_path):
    out = tmp_path / "again"
    (out).mkdir()
    import shutil

    shutil.copytree(reference_run / CACHE, out / CACHE)
    plant = read_plant(mini_plant)
    run = run_plant(plant, out, jobs=1)
    assert set(run.cached) == {*CELLS, "task"} and run.computed == ()
    write_plant_report(plant, out)
    assert cell_results(out) == cell_results(reference_run)


def _results(out: Path) -> set[Path]:
    return set((out / CACHE).glob(f"*/{RESULT}"))


def test_plant_resumes_after_kill_9_of_the_client(mini_plant, reference_run, tmp_path):
    out = tmp_path / "killed"
    client = subprocess.Popen(
        [sys.executable, "-m", "joulepath", "plant", str(mini_plant), "--out", str(out), "--jobs", "1"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 120
        while not _results(out) and client.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        os.kill(client.pid, signal.SIGKILL)  # halfway: one cell stored, the others not
        client.wait(timeout=30)
    finally:
        try:
            os.killpg(client.pid, signal.SIGKILL)  # the orphaned local cluster
        except ProcessLookupError:
            pass
    done = _results(out)
    assert 1 <= len(done) < len(CELLS), "the client was not killed halfway"
    plant = read_plant(mini_plant)
    keys = {t.key: t.name for t in plan_tasks(plant)}
    stored = {keys[p.parent.name] for p in done}
    run = run_plant(plant, out, jobs=1)
    assert set(run.computed) == {*CELLS, "task"} - stored and set(run.cached) == stored
    write_plant_report(plant, out)
    assert cell_results(out) == cell_results(reference_run)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _dask(*args: str) -> subprocess.Popen[bytes]:
    exe = Path(sys.executable).with_name("dask")
    return subprocess.Popen(
        [str(exe), *args], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True
    )


def test_plant_on_a_dask_scheduler_with_a_worker_killed_mid_task(mini_plant, reference_run, tmp_path):
    distributed = pytest.importorskip("distributed")
    address = f"tcp://127.0.0.1:{_free_port()}"
    port = address.rsplit(":", 1)[1]
    procs = [_dask("scheduler", "--host", "127.0.0.1", "--port", port, "--dashboard-address", "127.0.0.1:0")]
    out = tmp_path / "cluster"
    try:
        for _ in range(2):
            procs.append(_dask("worker", address, "--nthreads", "1", "--no-nanny", "--host", "127.0.0.1"))
        with distributed.Client(address, timeout="60s") as watch:
            watch.wait_for_workers(2, timeout=120)
            client = subprocess.Popen(
                [
                    sys.executable,
                    "-m",
                    "joulepath",
                    "plant",
                    str(mini_plant),
                    "--out",
                    str(out),
                    "--scheduler",
                    address,
                ],
                stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT,
            )
            killed = None
            deadline = time.monotonic() + 120
            while killed is None and client.poll() is None and time.monotonic() < deadline:
                busy = {w: keys for w, keys in watch.processing().items() if keys}
                if busy:
                    worker, keys = next(iter(busy.items()))
                    pids = watch.run(os.getpid, workers=[worker])
                    os.kill(pids[worker], signal.SIGKILL)
                    killed = str(keys[0])
                time.sleep(0.02)
            text = client.communicate(timeout=300)[0].decode()
        assert killed is not None, "no worker was seen running a task"
        assert client.returncode == 0, text  # every cell finishes, the killed one retried
    finally:
        for p in procs:
            p.kill()
            p.wait(timeout=30)
    key = killed.removeprefix("joulepath-cell-")
    assert (out / CACHE / key / RESULT).is_file() or (out / CACHE / key / "attempt.json").is_file()
    assert cell_results(out) == cell_results(reference_run)


def _chromium() -> str | None:
    import shutil

    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        found = shutil.which(name)
        if found:
            return found
    return None


def test_plant_report_renders_in_headless_chromium(reference_run, tmp_path):
    browser = _chromium()
    if browser is None:
        if os.environ.get("JOULEPATH_REQUIRE_BROWSER"):
            pytest.fail("JOULEPATH_REQUIRE_BROWSER is set but no chromium is installed")
        pytest.skip("no headless Chromium (Debian: apt-get install chromium)")
    check = """<script>window.addEventListener('load', () => {
      const out = {sections: [], width: document.documentElement.scrollWidth,
                   rows: document.querySelectorAll('#ranking tr').length};
      for (const s of document.querySelectorAll('section')) {
        const r = s.getBoundingClientRect();
        out.sections.push({id: s.id, height: r.height, text: s.innerText.trim().length});
      }
      const pre = document.createElement('pre'); pre.id = 'render-check';
      pre.textContent = JSON.stringify(out); document.body.appendChild(pre);});</script>"""
    page = tmp_path / "report.html"
    page.write_text((reference_run / "report.html").read_text().replace("</body>", check + "</body>"))
    import tempfile

    with tempfile.TemporaryDirectory() as profile:
        done = subprocess.run(
            [browser, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
             "--disable-background-networking", f"--user-data-dir={profile}", "--window-size=1280,900",
             "--virtual-time-budget=10000", "--dump-dom", page.as_uri()],
            capture_output=True, text=True, timeout=180, check=False,
        )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    start = done.stdout.index('<pre id="render-check">') + len('<pre id="render-check">')
    result = json.loads(done.stdout[start : done.stdout.index("</pre>", start)].replace("&quot;", '"'))
    assert [s["id"] for s in result["sections"]] == ["summary", "ranking", "energy", "programs"]
    assert all(s["height"] > 50 and s["text"] > 40 for s in result["sections"])
    assert result["rows"] == 1 + 4 and result["width"] <= 1280
