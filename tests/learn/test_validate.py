"""Model folders are checked before a library reads them: tampered files give one InvalidModel line.

A tampered XGBoost JSON used to crash the process (rc 139) at prediction time;
cards that did not match their model gave KeyError tracebacks or, with shuffled
input columns, silently wrong energies.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from joulepath.errors import InvalidInput, InvalidModel
from joulepath.learn import EnergyModel, check_finite_predictions, read_joints_json


def _copy(trained: Any, name: str, tmp_path: Path) -> Path:
    folder = tmp_path / name
    shutil.copytree(trained.models[name], folder)
    return folder


def _edit_json(path: Path, change: Callable[[Any], None]) -> None:
    doc = json.loads(path.read_text())
    change(doc)
    path.write_text(json.dumps(doc))


def _tree(doc: dict[str, Any], i: int = 0) -> dict[str, Any]:
    tree: dict[str, Any] = doc["learner"]["gradient_booster"]["model"]["trees"][i]
    return tree


def _internal(tree: dict[str, Any]) -> list[int]:
    return [i for i, c in enumerate(tree["left_children"]) if c != -1]


def _refused(folder: Path, pattern: str) -> str:
    with pytest.raises(InvalidModel, match=pattern) as info:
        EnergyModel.load(folder)
    message = str(info.value)
    assert "\n" not in message, message
    return message


# --------------------------------------------------------------------------- XGBoost trees
def _split_out_of_range(doc):
    tree = _tree(doc)
    tree["split_indices"][_internal(tree)[0]] = 10**6


def _left_child_out_of_range(doc):
    _tree(doc)["left_children"][0] = 10**6


def _right_child_negative(doc):
    _tree(doc)["right_children"][0] = -5


def _child_is_root(doc):
    _tree(doc)["left_children"][0] = 0


def _cycle(doc):
    """Turn a leaf B below an internal node A into a split whose children lead back to A."""
    tree = _tree(doc)
    a = next(i for i in _internal(tree) if i != 0)
    b = tree["left_children"][a]
    tree["left_children"][b] = a
    tree["right_children"][b] = a


def _shared_child(doc):
    tree = _tree(doc)
    tree["right_children"][0] = tree["left_children"][0]


def _num_feature(doc):
    doc["learner"]["learner_model_param"]["num_feature"] = "5"


def _tree_num_feature(doc):
    _tree(doc, 1)["tree_param"]["num_feature"] = "3"


def _short_array(doc):
    _tree(doc)["split_conditions"].pop()


def _num_nodes(doc):
    _tree(doc)["tree_param"]["num_nodes"] = str(len(_tree(doc)["left_children"]) + 7)


def _nan_leaf(doc):
    tree = _tree(doc)
    leaf = tree["left_children"].index(-1)
    tree["split_conditions"][leaf] = float("nan")


def _categorical(doc):
    _tree(doc)["split_type"][0] = 1


def _num_trees(doc):
    doc["learner"]["gradient_booster"]["model"]["trees"].pop()


def _string_child(doc):
    _tree(doc)["left_children"][0] = "1"


def _dart(doc):
    doc["learner"]["gradient_booster"]["name"] = "dart"


def _no_learner(doc):
    del doc["learner"]


@pytest.mark.parametrize(
    ("tamper", "pattern"),
    [
        (_split_out_of_range, r"tree 0: node \d+ splits on feature 1000000, but the model has 66 features"),
        (_left_child_out_of_range, r"tree 0: node 0 has left child 1000000, outside 1\.\.\d+"),
        (_right_child_negative, r"tree 0: node 0 has right child -5"),
        (_child_is_root, r"tree 0: node 0 has left child 0, outside"),
        (_cycle, r"tree 0: node \d+ is reached twice \(a cycle or a shared child\)"),
        (_shared_child, r"tree 0: node \d+ is reached twice"),
        (_num_feature, r"num_feature is 5, but the card's inputs give 66 model features"),
        (_tree_num_feature, r"tree 1: tree_param.num_feature differs"),
        (_short_array, r"tree 0: split_conditions has \d+ entries for \d+ nodes"),
        (_num_nodes, r"tree 0: left_children has \d+ entries for \d+ nodes"),
        (_nan_leaf, r"tree 0: split_conditions holds NaN"),
        (_categorical, r"tree 0: categorical splits"),
        (_num_trees, r"num_trees, trees and tree_info disagree"),
        (_string_child, r"tree 0: left_children holds values that are not integers"),
        (_dart, r"a 'dart' booster"),
        (_no_learner, r"not an XGBoost JSON model \(lacks 'learner'\)"),
    ],
)
def test_load_refuses_tampered_xgboost_trees(trained, tmp_path, tamper, pattern):
    folder = _copy(trained, "xgb-E", tmp_path)
    _edit_json(folder / "model.json", tamper)
    message = _refused(folder, pattern)
    assert str(folder / "model.json") in message


def test_load_refuses_xgboost_json_that_is_not_json(trained, tmp_path):
    folder = _copy(trained, "xgb-E", tmp_path)
    (folder / "model.json").write_bytes(b'{"learner": \xff')
    _refused(folder, r"model.json: not valid JSON")


def test_load_accepts_the_untampered_xgboost_model(trained, tmp_path, lab_tables):
    """The checks pass a real model unchanged (no false refusals) and it predicts as before."""
    folder = _copy(trained, "xgb-E", tmp_path)
    model = EnergyModel.load(folder)
    assert model.source == folder
    _, test = lab_tables
    X = test.frame[list(model.input_columns)].to_numpy()
    np.testing.assert_array_equal(
        model.predict_rows(X), EnergyModel.load(trained.models["xgb-E"]).predict_rows(X)
    )


_OPTIMIZE = ["optimize", "--start", "0,0,0,0,0,0", "--end", "0.3,0.2,0.1,0,0,0", "--duration", "1.5"]
_OPTIMIZE += ["--fitness", "surrogate", "--generations", "1", "--population", "4"]


@pytest.mark.parametrize("tamper", [_left_child_out_of_range, _cycle, _right_child_negative])
def test_cli_with_a_tampered_xgboost_model_exits_2_not_a_crash(trained, tmp_path, tamper):
    """The real process: exit 2 and one line, never a signal (rc < 0 or >= 128, e.g. 139 segfault)."""
    models = tmp_path / "models"
    _copy(trained, "xgb-E", models)
    _edit_json(models / "xgb-E" / "model.json", tamper)
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "joulepath",
            *_OPTIMIZE,
            "--model",
            str(models),
            "--out",
            str(tmp_path / "r"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert 0 <= proc.returncode < 128, proc.returncode
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "model.json: tree 0:" in lines[0], proc.stderr
    assert not (tmp_path / "r" / "path.mod").exists()


def test_load_refuses_xgboost_model_of_other_columns(trained, tmp_path):
    """The booster records its input names; a model file swapped in from another card is refused."""
    folder = _copy(trained, "xgb-E", tmp_path)

    def swap(doc):
        attrs = doc["learner"]["attributes"]
        cols = json.loads(attrs["joulepath_input_columns"])
        cols[0], cols[1] = cols[1], cols[0]
        attrs["joulepath_input_columns"] = json.dumps(cols)

    _edit_json(folder / "model.json", swap)
    _refused(folder, r"was trained on other input columns \(or another order\) than .*card.json lists")


# --------------------------------------------------------------------------- cards
def _shuffle(card):
    card["input_columns"][0], card["input_columns"][1] = card["input_columns"][1], card["input_columns"][0]


def _shuffle_old_card(card):
    _shuffle(card)
    del card["input_columns_sha256"]


def _drop_column(card):
    card["input_columns"].pop(3)
    del card["input_columns_sha256"]


def _rename_column(card):
    card["input_columns"][2] = "q9"
    del card["input_columns_sha256"]


def _duplicate_column(card):
    card["input_columns"][2] = card["input_columns"][1]
    del card["input_columns_sha256"]


def _no_cv_grouped(card):
    del card["cv_grouped"]


def _cv_grouped_text(card):
    card["cv_grouped"] = {"r2_mean": "high"}


def _family_unknown(card):
    card["family"] = "knn"


def _family_other(card):
    card["family"] = "mlp"


def _target_number(card):
    card["target"] = 7


def _feature_set_unknown(card):
    card["feature_set"] = "full41"


def _columns_not_list(card):
    card["input_columns"] = "q1,q2"


def _card_list(card):
    card.clear()


def _robot_number(card):
    card["robot_source"] = 7


@pytest.mark.parametrize(
    ("name", "tamper", "pattern"),
    [
        ("par-E", _shuffle, r"input_columns do not match the order the model was trained on"),
        ("xgb-E", _shuffle, r"input_columns do not match the order"),
        ("par-E", _shuffle_old_card, r"the input columns reordered \(position 1 is 'dq1', not 'q1'\)"),
        ("xgb-E", _shuffle_old_card, r"the input columns reordered \(position 1 is 'dq1', not 'q1'\)"),
        (
            "par-E",
            _drop_column,
            r"has 40 input columns \(unknown: none; missing: \w+; duplicates: 0\), but .* reads the 41",
        ),
        ("svr-E", _rename_column, r"unknown: q9; missing: \w+"),
        ("mlp-E", _duplicate_column, r"duplicates: 1"),
        ("par-E", _no_cv_grouped, r"the card lacks 'cv_grouped'; train the model again"),
        ("xgb-E", _cv_grouped_text, r"cv_grouped must be an object with a number r2_mean"),
        ("par-E", _family_unknown, r"family is 'knn', expected one of mlp, svr, par, xgb, bases"),
        ("par-E", _family_other, r"holds a SGDRegressor, but the card says family 'mlp'"),
        ("par-E", _target_number, r"target is 7, expected one of"),
        ("par-E", _feature_set_unknown, r"feature_set is 'full41'"),
        ("par-E", _columns_not_list, r"input_columns must be a list of column names"),
        ("par-E", _card_list, r"the card lacks 'family'"),
        ("xgb-E", _robot_number, r"robot_source must be a robot name, got 7"),
    ],
)
def test_load_refuses_a_card_that_does_not_match_its_model(trained, tmp_path, name, tamper, pattern):
    folder = _copy(trained, name, tmp_path)
    _edit_json(folder / "card.json", tamper)
    assert str(folder) in _refused(folder, pattern)


def test_load_refuses_a_card_that_is_not_an_object(trained, tmp_path):
    folder = _copy(trained, "par-E", tmp_path)
    (folder / "card.json").write_text("[1, 2]")
    _refused(folder, r"card.json: holds a JSON list, not an object")
    (folder / "card.json").write_bytes(b"\xff\xfe")
    _refused(folder, r"card.json: not valid JSON")


def test_load_refuses_a_card_whose_physics_columns_differ_from_the_pipeline(trained, tmp_path):
    """The skops pipeline's physics step knows the column order it was fitted with."""
    import skops.io as sio

    folder = _copy(trained, "mlp-E", tmp_path)
    pipeline = EnergyModel.load(folder).pipeline
    cols = list(pipeline.named_steps["physics"].columns)
    cols[0], cols[1] = cols[1], cols[0]
    pipeline.named_steps["physics"].columns = tuple(cols)
    sio.dump(pipeline, folder / "model.skops")
    _refused(
        folder, r"model.skops: the model was trained on other input columns than its card lists \(column 1"
    )


@pytest.mark.parametrize(
    ("name", "attr", "pattern"),
    [
        ("par-E", "coef_", r"the SGDRegressor's fitted arrays do not fit 66 model features"),
        ("mlp-E", "coefs_", r"the MLPRegressor's fitted arrays do not fit 66 model features"),
        ("svr-E", "coef_", r"the LinearSVR's fitted arrays do not fit 66 model features"),
        ("par-E", "mean_", r"the scaling step does not hold 66 means and scales"),
    ],
)
def test_load_refuses_fitted_arrays_of_the_wrong_shape(trained, tmp_path, name, attr, pattern):
    import skops.io as sio

    folder = _copy(trained, name, tmp_path)
    pipeline = EnergyModel.load(folder).pipeline
    model = pipeline.named_steps["model"]
    owner = {
        "coef_": getattr(model, "estimator_", model),
        "coefs_": model,
        "mean_": pipeline.named_steps["scale"],
    }[attr]
    value = getattr(owner, attr)
    if isinstance(value, list):
        value[0] = value[0][:-1]
    else:
        setattr(owner, attr, value[:-1])
    sio.dump(pipeline, folder / "model.skops")
    _refused(folder, pattern)


def test_load_refuses_non_finite_weights(trained, tmp_path):
    import skops.io as sio

    folder = _copy(trained, "par-E", tmp_path)
    pipeline = EnergyModel.load(folder).pipeline
    pipeline.named_steps["model"].coef_[4] = np.inf
    sio.dump(pipeline, folder / "model.skops")
    _refused(folder, r"SGDRegressor.coef_ holds NaN or infinite values")


@pytest.mark.parametrize("file", ["../model.skops", "/etc/passwd", "sub/model.skops", "..", "", 3])
def test_load_refuses_a_model_file_outside_the_folder(trained, tmp_path, file):
    folder = _copy(trained, "par-E", tmp_path)
    shutil.copy(folder / "model.skops", tmp_path / "model.skops")
    (folder / "sub").mkdir()
    shutil.copy(folder / "model.skops", folder / "sub" / "model.skops")
    _edit_json(folder / "card.json", lambda card: card.update(file=file))
    _refused(folder, r"(file must be the plain name of a file in the model folder|\.skops files only)")


def test_load_refuses_a_model_file_linked_from_outside(trained, tmp_path):
    folder = _copy(trained, "xgb-E", tmp_path)
    outside = tmp_path / "elsewhere.json"
    os.replace(folder / "model.json", outside)
    (folder / "model.json").symlink_to(outside)
    _refused(folder, r"model.json: is a link to .*elsewhere.json, outside the model folder")


def test_load_refuses_a_missing_model_file(trained, tmp_path):
    folder = _copy(trained, "par-E", tmp_path)
    (folder / "model.skops").unlink()
    _refused(folder, r"model.skops: the model file named by .*card.json is missing")


def test_best_model_refuses_a_folder_holding_a_broken_card(trained, tmp_path):
    """best_model reads cv_grouped of every card: a missing one is one line, not a KeyError."""
    from joulepath.learn import best_model

    root = tmp_path / "models"
    for name in ("par-E", "xgb-E"):
        _copy(trained, name, root)
    _edit_json(root / "xgb-E" / "card.json", _no_cv_grouped)
    with pytest.raises(InvalidModel, match=r"xgb-E/card.json: the card lacks 'cv_grouped'"):
        best_model(root, "E")


def test_saved_card_records_the_ordered_input_hash(trained):
    from joulepath.learn._validate import input_columns_sha256

    card = json.loads((trained.models["par-E"] / "card.json").read_text())
    assert card["input_columns_sha256"] == input_columns_sha256(card["input_columns"])
    assert input_columns_sha256(["a", "b"]) != input_columns_sha256(["b", "a"])


# --------------------------------------------------------------------------- predictions
def test_check_finite_predictions_returns_the_predictions(trained, lab_tables):
    _, test = lab_tables
    model = EnergyModel.load(trained.models["par-E"])
    X = test.frame[list(model.input_columns)].to_numpy()
    np.testing.assert_array_equal(check_finite_predictions(model, X), model.predict_rows(X))
    assert check_finite_predictions(model, X[:1]).shape == (1,)


def test_check_finite_predictions_refuses_nan_and_inf(trained, lab_tables):
    _, test = lab_tables
    loaded = EnergyModel.load(trained.models["mlp-E"])
    X = test.frame[list(loaded.input_columns)].to_numpy()[:5]
    pipeline = loaded.pipeline
    pipeline.named_steps["model"].coefs_[-1][:] = np.inf  # a diverged output layer
    model = EnergyModel(pipeline, loaded.card, source=loaded.source)
    pattern = (
        r"mlp-E: the mlp model for E predicts (-?inf|nan) for 5 of 5 rows \(first: row 0\); its energies"
    )
    with pytest.raises(InvalidModel, match=pattern):
        check_finite_predictions(model, X)
    par = EnergyModel.load(trained.models["par-E"])
    X = test.frame[list(par.input_columns)].to_numpy()[:4].copy()
    X[2, par.input_columns.index("x")] = 1e308  # overflows the scaled linear model on one row
    with pytest.raises(
        InvalidModel, match=r"the par model for E predicts (-?inf|nan) for 1 of 4 rows \(first: row 2\)"
    ):
        check_finite_predictions(par, X)


# --------------------------------------------------------------------------- joints.json
def test_read_joints_json_reads_what_train_writes(trained):
    joints = read_joints_json(trained.out_dir / "joints.json", 6)
    assert sorted(joints) == [1, 2, 3, 4, 5, 6]
    written = json.loads((trained.out_dir / "joints.json").read_text())["joints_by_influence"]
    assert joints == tuple(written)


@pytest.mark.parametrize(
    ("content", "pattern"),
    [
        (b"{", r"not valid JSON"),
        (b"\xff\xfe\x00", r"not valid JSON"),
        (b"[3, 2, 1]", r"expected an object with a non-empty list joints_by_influence"),
        (b"{}", r"expected an object with a non-empty list joints_by_influence"),
        (b'{"joints_by_influence": []}', r"non-empty list"),
        (b'{"joints_by_influence": "3,2,1"}', r"non-empty list"),
        (b'{"joints_by_influence": [3, "2", 1]}', r"holds '2', not a joint number 1\.\.6"),
        (b'{"joints_by_influence": [3, 0]}', r"holds 0, not a joint number 1\.\.6"),
        (b'{"joints_by_influence": [3, 7]}', r"holds 7, not a joint number 1\.\.6"),
        (b'{"joints_by_influence": [3, 2.0]}', r"holds 2.0, not a joint number"),
        (b'{"joints_by_influence": [true, 2]}', r"holds True, not a joint number"),
        (b'{"joints_by_influence": [3, 2, 3]}', r"lists joint 3 more than once"),
        (b'{"joints_by_influence": [1e400]}', r"holds inf, not a joint number"),
        (b"[" * 100000, r"not valid JSON"),
    ],
)
def test_read_joints_json_refuses_broken_files(tmp_path, content, pattern):
    path = tmp_path / "joints.json"
    path.write_bytes(content)
    with pytest.raises(InvalidModel, match=pattern) as info:
        read_joints_json(path, 6)
    assert str(path) in str(info.value) and "\n" not in str(info.value)


def test_read_joints_json_missing_file_and_bad_count(tmp_path):
    with pytest.raises(InvalidModel, match=r"joints.json: no such file"):
        read_joints_json(tmp_path / "joints.json", 6)
    (tmp_path / "joints.json").write_text('{"joints_by_influence": [2, 1]}')
    assert read_joints_json(tmp_path / "joints.json", 2) == (2, 1)
    with pytest.raises(InvalidModel, match=r"holds 2, not a joint number 1\.\.1"):
        read_joints_json(tmp_path / "joints.json", 1)
    with pytest.raises(InvalidInput, match="n_joints must be a positive integer"):
        read_joints_json(tmp_path / "joints.json", 0)
