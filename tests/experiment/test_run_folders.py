"""A run folder holds only what the current settings produce (issue 15, defect 3)."""

import json
import shutil
from pathlib import Path

import pandas as pd
import pytest

from joulepath.experiment import load_experiment, run_experiment
from joulepath.experiment._run import _Context, _robot_key, _stage

STAGES = ("data", "synth", "train", "importance", "optimize", "bench", "identify")


def _ctx(root: Path, said: list[str]) -> _Context:
    root.mkdir(parents=True, exist_ok=True)
    return _Context(exp=None, root=root, tell=said.append, progress=lambda *_a: None)  # type: ignore[arg-type]


def _writer(files: dict[str, str], cache: dict[str, str] | None = None):
    def body(folder: Path) -> dict:
        for name, text in files.items():
            (folder / name).parent.mkdir(parents=True, exist_ok=True)
            (folder / name).write_text(text)
        for name, text in (cache or {}).items():
            (folder / ".gridcache" / name).parent.mkdir(parents=True, exist_ok=True)
            (folder / ".gridcache" / name).write_text(text)
        return {}

    return body


def test_stage_folder_holds_only_what_the_current_settings_produce(tmp_path):
    said: list[str] = []
    ctx = _ctx(tmp_path / "run", said)
    # first settings: two model families, and a task whose move passed the limit check
    _stage(ctx, "train", "models", "k1", _writer({"par-E/card.json": "par", "xgb-E/card.json": "xgb"}))
    _stage(ctx, "optimize", "optimize", "k1", _writer({"task-000/path.mod": "MODULE"}))
    (ctx.root / "summary.json").write_text("{}")
    # new settings: one family; the task's move is refused, so no path.mod
    _stage(ctx, "train", "models", "k2", _writer({"xgb-E/card.json": "xgb"}))
    _stage(ctx, "optimize", "optimize", "k2", _writer({"task-000/result.json": "{}"}))
    models = sorted(p.name for p in (ctx.root / "models").iterdir())
    assert models == ["stage.json", "xgb-E"]
    assert not (ctx.root / "optimize" / "task-000" / "path.mod").exists()
    assert (ctx.root / "optimize" / "task-000" / "result.json").exists()
    assert not (ctx.root / "summary.json").exists(), "a stale summary outlives the stage it describes"
    assert sorted(p.name for p in ctx.root.iterdir()) == ["models", "optimize"]  # no .partial/.old left
    # the same settings again: skipped
    said.clear()
    _stage(ctx, "train", "models", "k2", _writer({"never.txt": "x"}))
    assert said == ["train: unchanged, skipped"] and not (ctx.root / "models" / "never.txt").exists()


def test_stage_interrupted_keeps_the_previous_folder_and_the_cache(tmp_path):
    ctx = _ctx(tmp_path / "run", [])
    _stage(ctx, "train", "models", "k1", _writer({"par-E/card.json": "par"}, cache={"par-E/a.json": "1"}))

    def interrupted(folder: Path) -> dict:
        (folder / ".gridcache" / "xgb-E").mkdir(parents=True)
        (folder / ".gridcache" / "xgb-E" / "b.json").write_text("2")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        _stage(ctx, "train", "models", "k2", interrupted)
    assert json.loads((ctx.root / "models" / "stage.json").read_text())["key"] == "k1"
    assert (ctx.root / "models" / "par-E" / "card.json").exists()
    seen: list[str] = []

    def resumed(folder: Path) -> dict:
        seen.extend(sorted(str(p.relative_to(folder)) for p in folder.rglob("*.json")))
        return {}

    _stage(ctx, "train", "models", "k2", resumed)
    assert seen == [".gridcache/par-E/a.json", ".gridcache/xgb-E/b.json"]  # caches only, no old model
    assert not (ctx.root / "models" / "par-E").exists()
    assert sorted(p.name for p in ctx.root.iterdir()) == ["models"]


def test_robot_key_follows_the_robot_file_content(tmp_path):
    from joulepath.description import preset_path

    robot = tmp_path / "arm.irml"
    robot.write_text(preset_path("irb120").read_text())
    before = _robot_key(str(robot))
    robot.write_text(robot.read_text().replace("<link-mass>3.067<", "<link-mass>3.1<"))
    assert _robot_key(str(robot)) != before
    assert _robot_key("irb120") == ["irb120"]


def test_run_experiment_dropped_family_and_stage_leave_nothing_behind(tiny_run, tiny_demo_toml, tmp_path):
    run = tmp_path / "run"
    shutil.copytree(tiny_run, run)
    assert (run / "models" / "par-E").is_dir() and (run / "synth").is_dir()
    changed = tiny_demo_toml(
        tmp_path, **{"train.targets": '["E"]', "families": '["mlp"]', "methods": "[]", "bench.tasks": "0"}
    )
    said: list[str] = []
    summary = run_experiment(load_experiment(changed), run, say=said.append)
    assert sorted(p.name for p in (run / "models").iterdir() if p.is_dir() and p.name[0] != ".") == ["mlp-E"]
    assert set(pd.read_csv(run / "models" / "results.csv")["family"]) == {"mlp"}
    assert not (run / "synth").exists() and not (run / "bench").exists()
    assert any(s.startswith("synth: no longer in the experiment") for s in said)
    ran = [s.split(":")[0] for s in said if s.split(":")[0] in STAGES and "done in" in s]
    # data and importance did not change; optimize uses physics fitness, so no model change reaches it;
    # identify compares the train stage's model and the synth stage's rows, so it runs again
    assert ran == ["train", "identify"]
    assert list(summary["stages"]) == ["data", "train", "importance", "optimize", "identify"]
    assert not [p for p in run.iterdir() if p.name.endswith((".partial", ".old", ".stale"))]
