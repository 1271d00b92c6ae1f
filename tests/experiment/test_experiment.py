"""Experiment files: validation up front, stages cached, the CLI."""

import json
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from joulepath.cli import main
from joulepath.errors import InvalidInput
from joulepath.experiment import load_experiment, run_experiment

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
STAGES = ("data", "synth", "train", "importance", "optimize", "bench")

TINY = """
name = "tiny"
seed = 1
[data]
train_moves = 15
test_moves = 6
[train]
families = ["par"]
cv = 3
[optimize]
tasks = 2
generations = 6
population = 12
"""


def _write(tmp_path, text, name="exp.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


@pytest.mark.parametrize(
    ("edit", "pattern"),
    [
        (lambda t: t.replace("cv = 3", "folds = 3"), r"\[train\] unknown key 'folds'; allowed: cv, families"),
        (
            lambda t: t.replace('families = ["par"]', 'families = "par"'),
            r"\[train\] families must be a list of strings",
        ),
        (lambda t: t.replace("tasks = 2", 'tasks = "two"'), r"\[optimize\] tasks must be an integer"),
        (
            lambda t: t.replace("[optimize]", '[optimize]\nalgorithm = "pso"'),
            r"algorithm = 'pso' is not allowed; use one of auto, gradient, cmaes, ga, de",
        ),
        (lambda t: t + "\n[plots]\nx = 1\n", r"unknown section \[plots\]; allowed: \[data\], \[synth\]"),
        (lambda t: t.replace('name = "tiny"', ""), r"missing key 'name'"),
        (lambda t: t.replace("[data]", "[data"), "not valid TOML"),
        (lambda t: t.replace("cv = 3", "cv = 0"), r"\[train\] cv must be ≥ 2"),
        (lambda t: t + '[synth]\nmethods = ["gan"]\n', r"\[synth\] methods has 'gan', which is not allowed"),
        (
            lambda t: t + '[synth]\nmethods = ["copula"]\n',
            r"source = 'micro' needs \[data\] micro_moves ≥ 1",
        ),
        (lambda t: t + "[synth]\nrepair = 1\n", r"\[synth\] repair must be true or false"),
        (lambda t: t.replace("seed = 1", "seed = 1\nrobot = 'nosuch'"), r"robot = 'nosuch'"),
        (
            lambda t: t.replace("[optimize]", "[optimize]\nrange_set = 'moon'"),
            r"range_set = 'moon' is not a range set of",
        ),
        (
            lambda t: t.replace("[optimize]", "[train]\n[optimize]").replace(
                'families = ["par"]', "families = []"
            ),
            "not valid TOML",
        ),
        (
            lambda t: t.replace('families = ["par"]', "families = []").replace(
                "[optimize]", '[optimize]\nfitness = "surrogate"'
            ),
            r"fitness = 'surrogate' needs models of E",
        ),
        (
            lambda t: t.replace("[optimize]", '[optimize]\nenergy = "meter"'),
            r"energy = 'meter' is not allowed; use one of thesis, mechanical, electrical",
        ),
        (
            lambda t: t.replace("[optimize]", '[optimize]\nenergy = "electrical"\nfitness = "surrogate"'),
            r"energy = 'electrical' needs fitness = 'physics'",
        ),
        (
            lambda t: t.replace("[data]", "[data]\ntrain_logs = ['nothere.csv']\ntest_logs = ['x.csv']"),
            r"train_logs names 'nothere.csv', which does not exist",
        ),
    ],
)
def test_load_experiment_errors(tmp_path, edit, pattern):
    with pytest.raises(InvalidInput, match=pattern):
        load_experiment(_write(tmp_path, edit(TINY)))


def test_electrical_energy_without_drive_data_is_refused_before_running(tmp_path):
    from joulepath.description import preset_path

    shutil.copy(preset_path("irb120", fmt="urdf"), tmp_path / "arm.urdf")  # no arm.drives.toml beside it
    text = TINY.replace("seed = 1", f"seed = 1\nrobot = '{tmp_path / 'arm.urdf'}'").replace(
        "[optimize]", '[optimize]\nrange_set = "nominal"\nenergy = "electrical"'
    )
    with pytest.raises(InvalidInput, match=r"\[optimize\] energy = 'electrical': .*needs drive data"):
        load_experiment(_write(tmp_path, text))
    exp = load_experiment(_write(tmp_path, text.replace('"electrical"', '"thesis"')))
    assert exp.optimize.energy == "thesis"


def test_bundled_demo_experiment_is_valid():
    from importlib import resources

    exp = load_experiment(str(resources.files("joulepath.experiment") / "presets" / "demo.toml"))
    assert exp.name == "demo" and exp.train.families == ("mlp", "svr", "par", "xgb")


def test_bundled_study_runs_the_demos_stages_at_a_larger_size():
    from importlib import resources

    presets = resources.files("joulepath.experiment") / "presets"
    demo = load_experiment(str(presets / "demo.toml"))
    study = load_experiment(str(presets / "study.toml"))
    assert study.name == "study"
    # every stage the demo runs, the study runs too, on at least as much data and work
    assert study.synth.methods and study.bench.tasks and study.identify.enabled and study.optimize.reference
    assert set(demo.synth.methods) <= set(study.synth.methods)
    assert study.train.families == demo.train.families and study.train.targets == demo.train.targets
    for a, b in (
        (demo.data.train_moves, study.data.train_moves),
        (demo.data.test_moves, study.data.test_moves),
        (demo.data.sim_moves, study.data.sim_moves),
        (demo.synth.rows, study.synth.rows),
        (demo.train.cv, study.train.cv),
        (demo.importance.max_rows, study.importance.max_rows),
        (demo.optimize.tasks, study.optimize.tasks),
        (demo.bench.tasks, study.bench.tasks),
        (demo.bench.generations, study.bench.generations),
        (demo.identify.loop_tasks, study.identify.loop_tasks),
    ):
        assert a <= b
    assert (study.data.train_moves, study.optimize.tasks, study.bench.tasks) > (
        demo.data.train_moves,
        demo.optimize.tasks,
        demo.bench.tasks,
    )


def test_bundled_thesis_experiment_is_the_full_plan():
    from importlib import resources

    exp = load_experiment(str(resources.files("joulepath.experiment") / "presets" / "thesis.toml"))
    assert (exp.data.train_moves, exp.data.test_moves, exp.data.micro_moves, exp.data.sim_moves) == (
        1000,
        100,
        100,
        1000,
    )
    assert exp.synth.rows == 75_000 and set(exp.synth.methods) == {"copula", "ctgan", "copulagan", "tvae"}
    assert exp.train.grid == "thesis" and exp.train.cv == 5 and len(exp.train.targets) == 7
    assert (exp.bench.tasks, exp.bench.generations, exp.bench.population) == (500, 250, 100)
    assert exp.bench.configurations == "thesis"


def test_tiny_demo_run_writes_every_stage(tiny_run):
    summary = json.loads((tiny_run / "summary.json").read_text())
    assert list(summary["stages"]) == [
        "data",
        "synth",
        "train",
        "importance",
        "optimize",
        "bench",
        "identify",
        "cycle",
    ]
    for folder in ("data", "synth", "models", "importance", "optimize", "bench", "identify", "cycle"):
        assert (tiny_run / folder / "stage.json").exists(), folder
    assert set(summary["stages"]["data"]["datasets"]) == {"train", "test", "micro", "sim"}
    assert (tiny_run / "synth" / "copula.parquet").exists()
    scores = pd.read_csv(tiny_run / "synth" / "scores.csv")
    assert scores["column_shapes"].between(0, 1).all()
    results = pd.read_csv(tiny_run / "models" / "results.csv")
    assert set(results["family"]) == {"par", "mlp"} and set(results["target"]) == {"E", "E1"}
    joints = json.loads((tiny_run / "importance" / "joints.json").read_text())["joints_by_influence"]
    assert sorted(joints) == [1, 2, 3, 4, 5, 6]
    tasks = pd.read_csv(tiny_run / "optimize" / "tasks.csv")
    assert len(tasks) == 2 and np.isfinite(tasks["saved_pct"]).all()
    for row in tasks.itertuples():
        assert (tiny_run / "optimize" / f"task-{row.task:03d}" / "path.mod").exists() == bool(row.limits_ok)
    # the identify stage reuses the train stage's best model of E and the synth stage's rows
    assert "the train stage's best model of E" in summary["stages"]["identify"]["learned_model"]
    compared = pd.read_csv(tiny_run / "identify" / "scores.csv")
    sdv_rows = len(pd.read_parquet(tiny_run / "synth" / "copula.parquet"))
    assert compared["trained_on"].str.startswith(f"{sdv_rows:,} rows, copula from the synth stage").any()
    bench = pd.read_csv(tiny_run / "bench" / "table.csv")
    assert len(bench) == 7 and bench["configuration"].str.startswith("MA").sum() == 2
    assert bench["configuration"].iloc[0] == "joulepath default (gradient)"
    runs = pd.read_csv(tiny_run / "bench" / "runs.csv")
    assert len(runs) == 7 * 2 and set(runs["task"]) == {0, 1}
    assert np.allclose(
        runs.groupby("configuration", sort=False)["vs_default"].mean(), bench["vs_default_mean"]
    )
    assert (tiny_run / "report.html").stat().st_size > 50_000
    assert not list(tiny_run.rglob("*.tmp*")), "a temporary file was left behind"


def test_run_experiment_skips_unchanged_stages_and_reruns_interrupted_ones(
    tiny_run, tiny_demo_toml, tmp_path
):
    run = tmp_path / "run"
    shutil.copytree(tiny_run, run)
    toml = tiny_demo_toml(tmp_path, **{"train.targets": '["E", "E1"]'})
    said: list[str] = []
    run_experiment(load_experiment(toml), run, say=said.append)
    skipped = [s for s in said if s.endswith("unchanged, skipped")]
    assert [s.split(":")[0] for s in skipped] == [
        "data",
        "synth",
        "train",
        "importance",
        "optimize",
        "bench",
        "identify",
    ]
    # a change in [optimize] reruns optimize only
    changed = tiny_demo_toml(tmp_path, **{"train.targets": '["E", "E1"]', "optimize.generations": "6"})
    said.clear()
    run_experiment(load_experiment(changed), run, say=said.append)
    ran = [s.split(":")[0] for s in said if s.split(":")[0] in STAGES and "done in" in s]
    assert ran == ["optimize"]
    # an interrupted stage (no stage.json) runs again; the stages after it that read it too
    (run / "importance" / "stage.json").unlink()
    said.clear()
    bars: list[tuple[str, int, int]] = []
    run_experiment(load_experiment(changed), run, say=said.append, progress=lambda *a: bars.append(a))
    assert bars[0] == ("importance", 0, 2) and bars[-1] == ("importance", 2, 2)  # targets E, E1
    ran = [s.split(":")[0] for s in said if s.split(":")[0] in STAGES and "done in" in s]
    assert ran == ["importance"]  # same settings: same key, so optimize and bench stay cached
    assert (run / "run.log").read_text().count("data: ") >= 3


def test_cli_run_errors_and_quiet(tmp_path, capsys):
    assert main(["run", str(tmp_path / "missing.toml")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no such experiment file" in err[0]
    bad = _write(tmp_path, TINY.replace("cv = 3", "folds = 3"), "bad.toml")
    assert main(["run", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "unknown key 'folds'" in err[0]
    assert not (tmp_path / "runs").exists()


def test_cli_quiet_run_prints_one_line(tiny_run, tiny_demo_toml, tmp_path, capsys):
    run = tmp_path / "run"
    shutil.copytree(tiny_run, run)
    toml = tiny_demo_toml(tmp_path, **{"train.targets": '["E", "E1"]'})
    assert main(["run", str(toml), "--out", str(run), "--quiet"]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert len(out) == 1 and out[0].startswith("demo: ") and out[0].endswith("report.html")


def test_an_interrupted_run_leaves_no_partial_file_and_resumes(
    tiny_run, tiny_demo_toml, tmp_path, monkeypatch
):
    import joulepath.optimize

    run = tmp_path / "run"
    shutil.copytree(tiny_run, run)
    changed = tiny_demo_toml(tmp_path, **{"train.targets": '["E", "E1"]', "optimize.generations": "7"})
    real_write_run = joulepath.optimize.write_run
    calls = []

    def interrupted(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt  # Ctrl-C while the second task is written
        return real_write_run(*args, **kwargs)

    monkeypatch.setattr(joulepath.optimize, "write_run", interrupted)
    before = sorted(p.relative_to(run) for p in (run / "optimize").rglob("*"))
    old_key = json.loads((run / "optimize" / "stage.json").read_text())["key"]
    with pytest.raises(KeyboardInterrupt):
        run_experiment(load_experiment(changed), run, say=lambda _t: None)
    # the previous complete optimize folder is untouched; the interrupted one is aside
    assert sorted(p.relative_to(run) for p in (run / "optimize").rglob("*")) == before
    assert json.loads((run / "optimize" / "stage.json").read_text())["key"] == old_key
    assert (run / ".optimize.partial").is_dir()
    assert not list(run.rglob("*.tmp*"))
    monkeypatch.setattr(joulepath.optimize, "write_run", real_write_run)
    said: list[str] = []
    run_experiment(load_experiment(changed), run, say=said.append)
    ran = [s.split(":")[0] for s in said if s.split(":")[0] in STAGES and "done in" in s]
    assert ran == ["optimize"]
    assert len(pd.read_csv(run / "optimize" / "tasks.csv")) == 2
    assert not (run / ".optimize.partial").exists() and not (run / ".optimize.old").exists()
    assert json.loads((run / "optimize" / "stage.json").read_text())["key"] != old_key


def test_run_on_a_dask_scheduler_gives_the_local_results(tmp_path, dask_scheduler):
    text = TINY.replace("[optimize]", '[optimize]\nfitness = "physics"').replace("tasks = 2", "tasks = 1")
    # seed 0: its random task (1.775 s) solves about 7 times faster than seed 1's (CPU time); the
    # run runs twice, and the scheduler must reproduce the local results whatever the seed
    text = text.replace("seed = 1", "seed = 0")
    text += "[bench]\ntasks = 1\ngenerations = 3\npopulation = 8\nconfigurations = 'compact'\n"
    # importance runs locally either way (the scheduler takes grid search and benchmark): E only, the
    # target whose joint ranking the optimizers use, not all seven
    text += '[importance]\ntargets = ["E"]\n'
    exp = load_experiment(_write(tmp_path, text))
    local = run_experiment(exp, tmp_path / "local", say=lambda _t: None)
    remote = run_experiment(exp, tmp_path / "dask", say=lambda _t: None, scheduler=dask_scheduler)
    assert remote["experiment"]["scheduler"].startswith("tcp://127.0.0.1")
    for name in ("models/results.csv", "bench/table.csv"):
        a = pd.read_csv(tmp_path / "local" / name).drop(columns=["search_s", "wall_s_mean"], errors="ignore")
        b = pd.read_csv(tmp_path / "dask" / name).drop(columns=["search_s", "wall_s_mean"], errors="ignore")
        pd.testing.assert_frame_equal(a, b)
    assert remote["mean_saved_pct"] == pytest.approx(local["mean_saved_pct"])


def test_cycle_stage_matches_its_files_and_the_report(tiny_run):
    """The [cycle] stage's record, its cycle.json and the report's section tell the same numbers."""
    import html as html_mod
    import re

    record = json.loads((tiny_run / "summary.json").read_text())["stages"]["cycle"]
    data = json.loads((tiny_run / "cycle" / "cycle.json").read_text())
    assert record["default_cycle_s"] == pytest.approx(data["default_cycle_s"])
    assert record["limits_ok"] == data["limits_ok"]
    if data["limits_ok"]:
        assert record["saved_pct"] == pytest.approx(data["saved_pct"])
        # the module is written exactly when the controller emulation runs it as planned
        matches = data["written_program_check"]["within_tolerances"]
        assert (tiny_run / "cycle" / "optimized.mod").is_file() == matches == record["program_written"]
        assert (data["rapid_refused"] is None) == matches
        # the per-move energies add up to the cycle's totals on physics
        moves = data["moves"]
        assert sum(m["optimized_energy_J"] for m in moves) <= data["energy_optimized_J"] + 1e-6
        # same cycle time (the default program's), never longer
        assert data["optimized_cycle_s"] <= data["default_cycle_s"] + 1e-6
    page = (tiny_run / "report.html").read_text()
    section = re.search(r'<section id="cycle".*?</section>', page, re.S)
    assert section is not None
    text = html_mod.unescape(section.group(0))
    assert f"{data['default_cycle_s']:.4g} s" in text
    assert ("REFUSED" in text) != data["limits_ok"]
    assert len(re.findall(r"<tr>", section.group(0))) >= len(data["moves"]) + 1
    # every measure of the cycle, named with its stage, in cycle.json and the report
    assert data["energies"]["thesis"]["default_J"] == pytest.approx(data["energy_default_J"])
    for name, m in data["energies"].items():
        assert f"{name} ({m['stage']})" in text


def test_cycle_section_is_checked_before_running(tmp_path, tiny_demo_toml):
    from joulepath.experiment import load_experiment

    toml = tiny_demo_toml(tmp_path)
    base = toml.read_text()
    (tmp_path / "p.mod").write_text("MODULE M\nENDMODULE\n")
    cases = {
        '[cycle]\nprogram = "missing.mod"\n': "does not exist",
        '[cycle]\nprogram = "p.mod"\npareto_points = 2\n': "pareto_points",
        '[cycle]\nprogram = "p.mod"\ncycle_time = -1.0\n': "cycle_time",
        '[cycle]\nprogram = "p.mod"\ncorridor_mm = nan\n': "corridor_mm",
        '[cycle]\ncell = "p.mod"\n': "program is not",
        '[cycle]\nprogram = "p.mod"\nspeed = 3\n': "unknown key",
    }
    for extra, words in cases.items():
        toml.write_text(base + "\n" + extra)
        with pytest.raises(InvalidInput, match=words):
            load_experiment(toml)
    # the program, the cell and the default cycle are read and checked now, not when the stage starts
    (tmp_path / "fast.toml").write_text(
        "start_deg = [0, 0, 0, 0, 30, 0]\n[[step]]\njoints_deg = [60, 20, 10, 0, 40, 0]\nduration_s = 0.05\n"
    )
    (tmp_path / "cell.toml").write_text('[[box]]\nname = "b"\ncenter_mm = [0, 0, 0]\n')
    late = {
        '[cycle]\nprogram = "p.mod"\n': r"\[cycle\] .*p\.mod",
        '[cycle]\nprogram = "fast.toml"\n': r"\[cycle\] .*duration_s = 0\.05 s is shorter",
        '[cycle]\nprogram = "good.mod"\ncell = "cell.toml"\n': r"\[cycle\] .*cell\.toml",
    }
    shutil.copy(EXAMPLES / "pick_and_place.mod", tmp_path / "good.mod")
    for extra, words in late.items():
        toml.write_text(base + "\n" + extra)
        with pytest.raises(InvalidInput, match=words):
            load_experiment(toml)
    toml.write_text(base + '\n[cycle]\nprogram = "good.mod"\ncycle_time = 5\n')
    assert load_experiment(toml).cycle.cycle_time == 5.0


def test_identify_section_needs_an_irml_robot_before_running(tmp_path, tiny_demo_toml):
    from joulepath.description import preset_path

    urdf = tmp_path / "arm.urdf"
    shutil.copy(preset_path("irb120", fmt="urdf"), urdf)
    toml = tiny_demo_toml(tmp_path, robot=f'"{urdf}"', **{"optimize.range_set": '"nominal"'})
    assert "enabled = true" in toml.read_text()  # the demo identifies a twin
    with pytest.raises(InvalidInput, match=r"\[identify\] needs a robot described in IRML"):
        load_experiment(toml)


def test_optimize_tasks_zero_runs(tiny_run, tiny_demo_toml, tmp_path):
    run = tmp_path / "run"
    shutil.copytree(tiny_run, run)
    toml = tiny_demo_toml(tmp_path, **{"train.targets": '["E", "E1"]', "optimize.tasks": "0"})
    summary = run_experiment(load_experiment(toml), run, say=lambda _t: None)
    assert summary["tasks"] == 0 and summary["mean_saved_pct"] is None
    assert list(pd.read_csv(run / "optimize" / "tasks.csv").columns)[:3] == [
        "task",
        "q_start_deg",
        "q_end_deg",
    ]
    assert (run / "report.html").is_file()


def test_a_missing_extra_is_refused_before_running(tmp_path, tiny_demo_toml, monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "casadi" else real(name, *a)
    )
    toml = tiny_demo_toml(tmp_path, **{"optimize.reference": "true", "optimize.fitness": '"physics"'})
    with pytest.raises(InvalidInput, match=r"optimize\.reference needs the optional package 'casadi'"):
        load_experiment(toml)
