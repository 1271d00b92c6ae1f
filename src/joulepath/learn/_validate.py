"""Checks that a model folder, its card, its model file and ``joints.json`` can be trusted.

Everything here runs before a file is handed to a library (XGBoost, scikit-learn)
and turns any inconsistency into one :class:`~joulepath.errors.InvalidModel` line
that names the file, what is wrong and how to fix it:

* the card: required keys with the right types, a known family, target, feature
  set and inputs, input columns in the order the model was trained on
  (``input_columns_sha256`` when the card has it, and the feature set's own order);
* the model file: a plain name inside the model folder (no ``../``, no absolute
  path, no symbolic link leading out);
* XGBoost JSON boosters: every tree's arrays of one length, split indices below
  ``num_feature``, child indices in range or ``-1``, each node reached once from
  the root (no cycles), numeric splits only, finite thresholds and leaf values,
  and ``num_feature`` equal to what the card's inputs give (XGBoost itself does
  not check these and crashes the process at prediction time);
* scikit-learn pipelines: the steps and array shapes the card implies;
* ``joints.json``: :func:`read_joints_json`.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from joulepath._typing import FloatArray
from joulepath.data import FEATURE_SETS, MAX_JOINTS, card_joints, target_columns
from joulepath.errors import InvalidInput, InvalidModel
from joulepath.learn._families import FAMILIES
from joulepath.learn._features import INPUTS, input_columns, n_kinematic_terms, n_physics_terms

_ROOT_PARENT = 2147483647
"""What XGBoost writes as the parent of a tree's root."""
_SVR_KERNELS = frozenset({"linear", "poly", "rbf", "sigmoid"})


def input_columns_sha256(columns: Sequence[str]) -> str:
    """SHA-256 of the ordered input names, as a card stores it."""
    return hashlib.sha256(json.dumps(list(columns)).encode()).hexdigest()


def n_model_features(n_inputs: int, inputs: str, n_joints: int = 6) -> int:
    """Columns the estimator sees: the inputs, plus the physics (or kinematic) terms."""
    if inputs == "physics":
        return n_inputs + n_physics_terms(n_joints)
    if inputs == "kinematic":
        return n_inputs + n_kinematic_terms(n_joints)
    return n_inputs


# --------------------------------------------------------------------------- card
def _first_difference(trained: Sequence[str], listed: Sequence[str]) -> str:
    for i, (a, b) in enumerate(zip(trained, listed, strict=False)):
        if a != b:
            return f"column {i + 1} is {a!r} in the model, {b!r} on the card"
    return f"{len(trained)} columns in the model, {len(listed)} on the card"


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and not math.isnan(value)


def check_card(card: Any, card_path: Path) -> dict[str, Any]:
    """Refuse a card with missing keys, wrong types, unknown values or reordered inputs."""
    if not isinstance(card, dict):
        raise InvalidModel(f"{card_path}: holds a JSON {type(card).__name__}, not an object; train again")
    for key in ("family", "target", "input_columns", "feature_set", "inputs", "file", "cv_grouped"):
        if key not in card:
            raise InvalidModel(f"{card_path}: the card lacks {key!r}; train the model again")
    choices: tuple[tuple[str, Sequence[str]], ...] = (
        ("family", FAMILIES),
        ("target", target_columns(MAX_JOINTS)),
        ("feature_set", tuple(FEATURE_SETS)),
        ("inputs", INPUTS),
    )
    for key, allowed in choices:
        if not isinstance(card[key], str) or card[key] not in allowed:
            raise InvalidModel(
                f"{card_path}: {key} is {card[key]!r}, expected one of {', '.join(allowed)}; "
                "the card was edited or comes from another tool"
            )
    for key in ("robot", "robot_source"):
        if key in card and card[key] is not None and not isinstance(card[key], str):
            raise InvalidModel(f"{card_path}: {key} must be a robot name, got {card[key]!r}")
    cv = card["cv_grouped"]
    if not isinstance(cv, dict) or not _is_number(cv.get("r2_mean")):
        raise InvalidModel(
            f"{card_path}: cv_grouped must be an object with a number r2_mean (the grouped-CV R² "
            f"used to pick the best model), got {cv!r}; train the model again"
        )
    cols = card["input_columns"]
    if not isinstance(cols, list) or not all(isinstance(c, str) for c in cols):
        raise InvalidModel(f"{card_path}: input_columns must be a list of column names, got {cols!r}")
    expected = list(input_columns(card["feature_set"], card["inputs"], card_joints(cols), card["family"]))
    stored = card.get("input_columns_sha256")
    if stored is not None and stored != input_columns_sha256(cols):
        raise InvalidModel(
            f"{card_path}: input_columns do not match the order the model was trained on "
            "(input_columns_sha256 differs); restore the card or train the model again"
        )
    if cols != expected:
        extra = [c for c in cols if c not in expected]
        missing = [c for c in expected if c not in cols]
        if extra or missing or len(cols) != len(expected):
            what = (
                f"{len(cols)} input columns (unknown: {', '.join(extra) or 'none'}; missing: "
                f"{', '.join(missing) or 'none'}; duplicates: {len(cols) - len(set(cols))})"
            )
        else:
            first = next(i for i, (a, b) in enumerate(zip(cols, expected, strict=True)) if a != b)
            what = (
                f"the input columns reordered (position {first + 1} is {cols[first]!r}, "
                f"not {expected[first]!r})"
            )
        raise InvalidModel(
            f"{card_path}: has {what}, but a model of feature set {card['feature_set']!r} with "
            f"{card['inputs']!r} inputs reads the {len(expected)} columns {expected[0]}..{expected[-1]} "
            "in the feature set's order; restore the card or train the model again"
        )
    return card


def model_file(folder: Path, card: dict[str, Any], card_path: Path) -> Path:
    """The model file the card names; it must be a plain file name inside ``folder``."""
    name = card["file"]
    plain = isinstance(name, str) and name not in ("", ".", "..") and "\\" not in name
    if not plain or Path(name).name != name:
        raise InvalidModel(
            f"{card_path}: file must be the plain name of a file in the model folder "
            f"(model.json or model.skops), got {name!r}"
        )
    path = folder / name
    if not path.is_file():
        raise InvalidModel(f"{path}: the model file named by {card_path} is missing; train the model again")
    real_folder = Path(os.path.realpath(folder))
    real = Path(os.path.realpath(path))
    if real.parent != real_folder:
        raise InvalidModel(
            f"{path}: is a link to {real}, outside the model folder {folder}; copy the file into the folder"
        )
    return Path(path)


# --------------------------------------------------------------------------- XGBoost JSON
def _int(value: Any, where: str) -> int:
    try:
        out = int(value)
    except (TypeError, ValueError, OverflowError) as err:
        raise InvalidModel(f"{where} is {value!r}, not an integer") from err
    if isinstance(value, bool) or (isinstance(value, float) and value != out):
        raise InvalidModel(f"{where} is {value!r}, not an integer")
    return out


def _int_array(tree: dict[str, Any], key: str, n: int, where: str) -> np.ndarray:
    values = tree.get(key)
    if not isinstance(values, list):
        raise InvalidModel(f"{where}: {key} is missing or not a list")
    if len(values) != n:
        raise InvalidModel(f"{where}: {key} has {len(values)} entries for {n} nodes")
    if not all(isinstance(v, int) and not isinstance(v, bool) for v in values):
        raise InvalidModel(f"{where}: {key} holds values that are not integers")
    return np.asarray(values, dtype=np.int64) if values else np.zeros(0, dtype=np.int64)


def _float_array(tree: dict[str, Any], key: str, n: int, where: str, *, finite: bool = True) -> FloatArray:
    values = tree.get(key)
    if not isinstance(values, list):
        raise InvalidModel(f"{where}: {key} is missing or not a list")
    if len(values) != n:
        raise InvalidModel(f"{where}: {key} has {len(values)} entries for {n} nodes")
    if not all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
        raise InvalidModel(f"{where}: {key} holds values that are not numbers")
    out = np.asarray(values, dtype=np.float64)
    if finite and not np.all(np.isfinite(out)):
        raise InvalidModel(f"{where}: {key} holds NaN or infinite values")
    return out


def _check_tree(tree: Any, where: str, n_features: int) -> None:
    if not isinstance(tree, dict) or not isinstance(tree.get("tree_param"), dict):
        raise InvalidModel(f"{where}: not a tree object with tree_param")
    param = tree["tree_param"]
    n = _int(param.get("num_nodes"), f"{where}: tree_param.num_nodes")
    if n < 1:
        raise InvalidModel(f"{where}: {n} nodes; a tree has at least its root")
    if _int(param.get("num_feature"), f"{where}: tree_param.num_feature") != n_features:
        raise InvalidModel(f"{where}: tree_param.num_feature differs from the model's ({n_features})")
    if _int(param.get("size_leaf_vector", 1), f"{where}: tree_param.size_leaf_vector") not in (0, 1):
        raise InvalidModel(f"{where}: vector leaves; joulepath models predict one value per row")
    n_deleted = _int(param.get("num_deleted", 0), f"{where}: tree_param.num_deleted")
    left = _int_array(tree, "left_children", n, where)
    right = _int_array(tree, "right_children", n, where)
    parents = _int_array(tree, "parents", n, where)
    split = _int_array(tree, "split_indices", n, where)
    kind = _int_array(tree, "split_type", n, where)
    _int_array(tree, "default_left", n, where)
    for key in ("split_conditions", "base_weights"):  # thresholds and leaf values
        _float_array(tree, key, n, where)
    for key in ("loss_changes", "sum_hessian"):  # statistics only
        _float_array(tree, key, n, where, finite=False)
    for key in ("left_children", "right_children"):
        children = left if key == "left_children" else right
        bad = np.flatnonzero((children != -1) & ((children < 1) | (children >= n)))
        if bad.size:
            raise InvalidModel(
                f"{where}: node {bad[0]} has {key[:-9]} child {children[bad[0]]}, outside 1..{n - 1} "
                "(or -1 for a leaf); the model file is damaged or was edited"
            )
    half = np.flatnonzero((left == -1) != (right == -1))
    if half.size:
        raise InvalidModel(f"{where}: node {half[0]} has one child; the model file is damaged or was edited")
    bad = np.flatnonzero((split < 0) | (split >= n_features))
    if bad.size:
        raise InvalidModel(
            f"{where}: node {bad[0]} splits on feature {split[bad[0]]}, but the model has "
            f"{n_features} features (0..{n_features - 1}); the model file is damaged or was edited"
        )
    if np.any(kind != 0):
        raise InvalidModel(f"{where}: categorical splits; joulepath models only use numeric splits")
    seen = np.zeros(n, dtype=bool)
    seen[0] = True
    stack = [0]
    while stack:
        node = stack.pop()
        for child in (int(left[node]), int(right[node])):
            if child == -1:
                continue
            if seen[child]:
                raise InvalidModel(
                    f"{where}: node {child} is reached twice (a cycle or a shared child); "
                    "the model file is damaged or was edited"
                )
            if parents[child] != node:
                raise InvalidModel(f"{where}: node {child} names parent {parents[child]}, not {node}")
            seen[child] = True
            stack.append(child)
    if parents[0] != _ROOT_PARENT:
        raise InvalidModel(f"{where}: the root names parent {parents[0]}; the model file is damaged")
    unreached = int(n - seen.sum())
    if unreached > n_deleted:
        raise InvalidModel(
            f"{where}: {unreached} node(s) are not reachable from the root (deleted: {n_deleted}); "
            "the model file is damaged or was edited"
        )


def check_xgboost_json(path: Path, *, n_features: int) -> dict[str, Any]:
    """Check an XGBoost JSON booster's structure before XGBoost reads it; return the parsed JSON.

    Parameters
    ----------
    path : Path
        ``model.json``.
    n_features : int
        Columns the booster must read (from the card).

    Raises
    ------
    InvalidModel
        Not JSON, not a single-target ``gbtree`` booster, a ``num_feature`` other than
        ``n_features``, or any tree that is out of range, cyclic or inconsistent.
    """
    try:
        doc = json.loads(path.read_bytes())
    except (json.JSONDecodeError, UnicodeDecodeError, RecursionError) as err:
        raise InvalidModel(f"{path}: not valid JSON ({err}); train the model again") from err
    where = str(path)
    try:
        learner = doc["learner"]
        param = learner["learner_model_param"]
        booster = learner["gradient_booster"]
        name = booster["name"]
    except (KeyError, TypeError) as err:
        raise InvalidModel(f"{where}: not an XGBoost JSON model (lacks {err}); train it again") from err
    if name != "gbtree":
        raise InvalidModel(f"{where}: a {name!r} booster; joulepath trains and reads gbtree boosters only")
    num_feature = _int(param.get("num_feature") if isinstance(param, dict) else None, f"{where}: num_feature")
    if num_feature != n_features:
        raise InvalidModel(
            f"{where}: num_feature is {num_feature}, but the card's inputs give {n_features} model "
            "features; the card and the model file do not belong together, train the model again"
        )
    if _int(param.get("num_target", 1), f"{where}: num_target") != 1 or _int(
        param.get("num_class", 0), f"{where}: num_class"
    ) not in (0, 1):
        raise InvalidModel(f"{where}: predicts several values per row; joulepath models predict one")
    try:
        model = booster["model"]
        trees = model["trees"]
        info = model["tree_info"]
        n_trees = _int(model["gbtree_model_param"]["num_trees"], f"{where}: num_trees")
    except (KeyError, TypeError) as err:
        raise InvalidModel(f"{where}: the booster lacks {err}; train the model again") from err
    if not isinstance(trees, list) or not isinstance(info, list) or not len(trees) == len(info) == n_trees:
        raise InvalidModel(f"{where}: num_trees, trees and tree_info disagree; train the model again")
    if any(v != 0 for v in info):
        raise InvalidModel(f"{where}: tree_info names output groups other than 0; joulepath predicts one")
    indptr = model.get("iteration_indptr")
    if indptr is not None:
        ok = isinstance(indptr, list) and all(isinstance(v, int) and not isinstance(v, bool) for v in indptr)
        if not ok or indptr[:1] != [0] or indptr[-1] != n_trees or np.any(np.diff(indptr) < 0):
            raise InvalidModel(f"{where}: iteration_indptr does not index the {n_trees} trees")
    for i, tree in enumerate(trees):
        _check_tree(tree, f"{where}: tree {i}", num_feature)
    return dict(doc)


# --------------------------------------------------------------------------- scikit-learn
def _shape(obj: Any, attr: str) -> tuple[int, ...] | None:
    value = getattr(obj, attr, None)
    return None if value is None else tuple(np.shape(value))


def _finite(obj: Any, attrs: Sequence[str], where: str) -> None:
    for attr in attrs:
        values = getattr(obj, attr, None)
        if values is None:
            continue
        arrays = values if isinstance(values, list | tuple) else [values]
        for a in arrays:
            if not np.all(np.isfinite(np.asarray(a, dtype=np.float64))):
                raise InvalidModel(f"{where}: {type(obj).__name__}.{attr} holds NaN or infinite values")


def check_pipeline(pipeline: Any, card: dict[str, Any], path: Path) -> None:
    """Check that a loaded scikit-learn pipeline has the steps and shapes its card implies."""
    from sklearn.linear_model import SGDRegressor
    from sklearn.neural_network import MLPRegressor
    from sklearn.preprocessing import StandardScaler
    from sklearn.svm import SVR, LinearSVR

    from joulepath.learn._features import KinematicFeatures, PhysicsFeatures
    from joulepath.learn._svr import ScalableSVR

    where = str(path)
    steps = dict(pipeline.steps)
    names = [name for name, _ in pipeline.steps]
    physics = card["inputs"] == "physics"
    kinematic = card["inputs"] == "kinematic"
    bases = card["family"] == "bases"
    expected = (["physics"] if physics else ["kinematic"] if kinematic else []) + (
        ["model"] if bases else ["scale", "model"]
    )
    if names != expected:
        raise InvalidModel(
            f"{where}: pipeline steps {names}, but a {card['family']} model with {card['inputs']!r} "
            f"inputs has {expected}; the card and the model file do not belong together"
        )
    cols = tuple(card["input_columns"])
    n_in = len(cols)
    n = n_model_features(n_in, card["inputs"], card_joints(cols))
    if physics:
        phys = steps["physics"]
        if not isinstance(phys, PhysicsFeatures) or not hasattr(phys, "index_"):
            raise InvalidModel(f"{where}: the physics step is not a fitted PhysicsFeatures")
        trained = (
            tuple(phys.columns)
            if phys.columns is not None
            else input_columns("full40", "physics", card_joints(cols))
        )
        if trained != cols:
            raise InvalidModel(
                f"{where}: the model was trained on other input columns than its card lists "
                f"({_first_difference(trained, cols)}); restore the card or train the model again"
            )
    if kinematic:
        kin = steps["kinematic"]
        if not isinstance(kin, KinematicFeatures) or not hasattr(kin, "index_"):
            raise InvalidModel(f"{where}: the kinematic step is not a fitted KinematicFeatures")
        if kin.columns is None or tuple(kin.columns) != cols:
            raise InvalidModel(
                f"{where}: the model was trained on other input columns than its card lists; "
                "restore the card or train the model again"
            )
    first = steps[names[0]]
    if getattr(first, "n_features_in_", n_in) != n_in:
        raise InvalidModel(
            f"{where}: the model reads {first.n_features_in_} input columns, the card lists {n_in}; "
            "the card and the model file do not belong together"
        )
    if bases:
        _check_bases(steps["model"], card, n, where)
        return
    scaler = steps["scale"]
    shapes = (_shape(scaler, "mean_"), _shape(scaler, "scale_"))
    if not isinstance(scaler, StandardScaler) or shapes != ((n,), (n,)):
        raise InvalidModel(
            f"{where}: the scaling step does not hold {n} means and scales ({n_in} inputs"
            + (" + the physics terms)" if physics else " + the kinematic terms)" if kinematic else ")")
        )
    _finite(scaler, ("mean_", "scale_"), where)
    model = steps["model"]
    family = card["family"]
    kinds: dict[str, tuple[type, ...]] = {
        "mlp": (MLPRegressor,),
        "par": (SGDRegressor,),
        "svr": (ScalableSVR, SVR),
    }
    try:
        from sklearn.linear_model import PassiveAggressiveRegressor

        kinds["par"] += (PassiveAggressiveRegressor,)
    except ImportError:  # removed in scikit-learn 1.10
        pass
    if family not in kinds or not isinstance(model, kinds[family]):
        raise InvalidModel(
            f"{where}: holds a {type(model).__name__}, but the card says family {family!r}; "
            "the card and the model file do not belong together"
        )
    wrong = f"{where}: the {type(model).__name__}'s fitted arrays do not fit {n} model features"
    if isinstance(model, MLPRegressor):
        coefs, intercepts = getattr(model, "coefs_", None), getattr(model, "intercepts_", None)
        if not isinstance(coefs, list) or not isinstance(intercepts, list) or len(coefs) != len(intercepts):
            raise InvalidModel(wrong)
        width = n
        for w, b in zip(coefs, intercepts, strict=True):
            if np.ndim(w) != 2 or np.shape(w)[0] != width or np.shape(b) != (np.shape(w)[1],):
                raise InvalidModel(wrong)
            width = np.shape(w)[1]
        if width != 1 or model.activation not in ("identity", "relu", "tanh", "logistic"):
            raise InvalidModel(wrong)
        _finite(model, ("coefs_", "intercepts_"), where)
        return
    if isinstance(model, ScalableSVR):
        inner = getattr(model, "estimator_", None)
        if not isinstance(inner, LinearSVR | SVR):
            raise InvalidModel(f"{where}: the ScalableSVR is not fitted; train the model again")
        model = inner
        wrong = f"{where}: the {type(model).__name__}'s fitted arrays do not fit {n} model features"
    if isinstance(model, SVR):
        n_sv = _shape(model, "support_vectors_")
        ok = (
            model.kernel in _SVR_KERNELS
            and n_sv is not None
            and len(n_sv) == 2
            and n_sv[1] == n
            and _shape(model, "_dual_coef_") == (1, n_sv[0])
            and _shape(model, "dual_coef_") == (1, n_sv[0])
            and _shape(model, "support_") == (n_sv[0],)
            and _shape(model, "_intercept_") == (1,)
            and _shape(model, "_n_support") == (2,)
            and int(np.sum(model._n_support)) == n_sv[0]
        )
        if not ok:
            raise InvalidModel(wrong)
        _finite(model, ("support_vectors_", "_dual_coef_", "_intercept_"), where)
        return
    if _shape(model, "coef_") != (n,) or _shape(model, "intercept_") not in ((1,), ()):
        raise InvalidModel(wrong)
    _finite(model, ("coef_", "intercept_"), where)


def _check_bases(model: Any, card: dict[str, Any], n_features: int, where: str) -> None:
    """Check a loaded :class:`~joulepath.learn.JointEnergyBases` against its card."""
    from joulepath.learn._bases import N_KINEMATIC_BASES, JointEnergyBases

    if not isinstance(model, JointEnergyBases):
        raise InvalidModel(
            f"{where}: holds a {type(model).__name__}, but the card says family 'bases'; "
            "the card and the model file do not belong together"
        )
    cols = tuple(card["input_columns"])
    if model.columns is None or tuple(model.columns) != cols or model.inputs != card["inputs"]:
        raise InvalidModel(
            f"{where}: the model was trained on other input columns than its card lists; "
            "restore the card or train the model again"
        )
    n_joints = card_joints(cols)
    per_joint = N_KINEMATIC_BASES + (2 if card["inputs"] == "physics" else 0)
    joints = getattr(model, "joints_", None)
    coef = getattr(model, "coef_", None)
    wrong = f"{where}: the JointEnergyBases' fitted arrays do not fit a {n_joints}-joint arm"
    if not isinstance(joints, np.ndarray) or joints.ndim != 1 or not isinstance(coef, np.ndarray):
        raise InvalidModel(wrong)
    total = joints.tolist() == [0]
    ok = (
        getattr(model, "n_features_in_", None) == n_features
        and (total or (len(set(joints.tolist())) == joints.size and joints.min() >= 1))
        and joints.max() <= n_joints
        and coef.shape == (joints.size, per_joint * (n_joints if total else 1))
    )
    if not ok:
        raise InvalidModel(wrong)
    _finite(model, ("coef_",), where)


# --------------------------------------------------------------------------- joints.json
def read_joints_json(path: str | os.PathLike[str], n_joints: int) -> tuple[int, ...]:
    """Joints (1-based) ordered by influence, from a ``joints.json`` written by training or importance.

    Parameters
    ----------
    path : path
        The ``joints.json`` file: ``{"target": "E", "joints_by_influence": [3, 2, ...]}``.
    n_joints : int
        Joints of the robot; every entry must lie in ``1..n_joints``.

    Returns
    -------
    tuple of int
        Distinct joint numbers, most influential first.

    Raises
    ------
    InvalidModel
        Not readable, not JSON, no ``joints_by_influence`` list, an entry that is not
        an integer in ``1..n_joints``, or a joint listed twice.
    """
    p = Path(path)
    if isinstance(n_joints, bool) or not isinstance(n_joints, int) or n_joints < 1:
        raise InvalidInput(f"n_joints must be a positive integer, got {n_joints!r}")
    fix = "run `joulepath train` or `joulepath importance` again to rewrite it"
    try:
        data = json.loads(p.read_bytes())
    except FileNotFoundError as err:
        raise InvalidModel(f"{p}: no such file; {fix}") from err
    except OSError as err:
        raise InvalidModel(f"{p}: cannot be read ({err.strerror}); {fix}") from err
    except (json.JSONDecodeError, UnicodeDecodeError, RecursionError) as err:
        raise InvalidModel(f"{p}: not valid JSON ({err}); {fix}") from err
    joints = data.get("joints_by_influence") if isinstance(data, dict) else None
    if not isinstance(joints, list) or not joints:
        raise InvalidModel(f"{p}: expected an object with a non-empty list joints_by_influence; {fix}")
    bad = [j for j in joints if isinstance(j, bool) or not isinstance(j, int) or not 1 <= j <= n_joints]
    if bad:
        raise InvalidModel(
            f"{p}: joints_by_influence holds {bad[0]!r}, not a joint number 1..{n_joints}; {fix}"
        )
    twice = sorted({j for j in joints if joints.count(j) > 1})
    if twice:
        raise InvalidModel(f"{p}: joints_by_influence lists joint {twice[0]} more than once; {fix}")
    return tuple(int(j) for j in joints)
