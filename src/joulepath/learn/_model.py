"""A fitted energy model: fast batch prediction, safe files, and a card that says what it is.

Files (one folder per model):

* ``model.skops`` — scikit-learn pipelines, written with skops; loading checks the
  file's types against an allowlist first and refuses anything else, so it never
  runs code from the file;
* ``model.json`` — XGBoost boosters in XGBoost's own JSON format (no pickle);
* ``card.json`` — feature names in order (and their SHA-256), feature set and
  inputs, units, target, training-data hash, CV and test metrics,
  hyperparameters, library versions.

Loading checks the card and the model file against each other before either
reaches a library (:mod:`joulepath.learn._validate`); :func:`check_finite_predictions`
refuses a model's NaN or infinite predictions.
"""

from __future__ import annotations

import json
import os
import platform
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from sklearn.pipeline import Pipeline
from sklearn.svm import LinearSVR

from joulepath._io import atomic_write_bytes, atomic_write_text, make_folder
from joulepath._typing import FloatArray
from joulepath.data import card_joints
from joulepath.errors import InvalidModel, MissingDependency
from joulepath.learn._features import (
    PHYSICS_VERSION,
    KinematicFeatures,
    PhysicsFeatures,
    kinematic_transform,
    physics_transform,
)
from joulepath.learn._svr import ScalableSVR
from joulepath.learn._validate import (
    check_card,
    check_pipeline,
    check_xgboost_json,
    input_columns_sha256,
    model_file,
    n_model_features,
)

CARD_VERSION = 1
TRUSTED_TYPES = frozenset(
    {
        "joulepath.learn._bases.JointEnergyBases",
        "joulepath.learn._features.KinematicFeatures",
        "joulepath.learn._features.PhysicsFeatures",
        "joulepath.learn._svr.ScalableSVR",
        "sklearn.neural_network._stochastic_optimizers.AdamOptimizer",
        "sklearn.neural_network._stochastic_optimizers.SGDOptimizer",
    }
)
"""Types outside scikit-learn/NumPy that a model file may contain."""
_XGB_COLUMNS_ATTR = "joulepath_input_columns"
"""Booster attribute holding the ordered input names (JSON), checked against the card on load."""

_ACTIVATIONS: dict[str, Callable[[FloatArray], FloatArray]] = {
    "identity": lambda z: z,
    "relu": lambda z: np.maximum(z, 0.0),
    "tanh": np.tanh,
    "logistic": lambda z: 1.0 / (1.0 + np.exp(-z)),
}


def library_versions() -> dict[str, str]:
    import sklearn

    out = {"python": platform.python_version(), "numpy": np.__version__, "scikit-learn": sklearn.__version__}
    try:
        import xgboost

        out["xgboost"] = xgboost.__version__
    except ImportError:
        pass
    try:
        import skops

        out["skops"] = skops.__version__
    except ImportError:
        pass
    return out


@dataclass(frozen=True, slots=True)
class _Forward:
    """The fitted arrays of an MLP pipeline, for a NumPy forward pass."""

    physics: PhysicsFeatures | KinematicFeatures | None
    mean: FloatArray
    scale: FloatArray
    weights: tuple[FloatArray, ...]
    biases: tuple[FloatArray, ...]
    activation: str


class EnergyModel:
    """A fitted pipeline that predicts one energy target (J per row) from table rows.

    Attributes
    ----------
    pipeline : sklearn Pipeline
    card : dict
        ``family``, ``target``, ``feature_set``, ``inputs``, ``input_columns``,
        ``robot``, metrics and versions (see the module docstring).
    source : Path or None
        The folder the model was loaded from (for messages).
    """

    def __init__(self, pipeline: Pipeline, card: dict[str, Any], *, source: Path | None = None) -> None:
        self.pipeline = pipeline
        self.card = card
        self.source = source
        self._forward = self._mlp_forward()

    @property
    def target(self) -> str:
        return str(self.card["target"])

    @property
    def family(self) -> str:
        return str(self.card["family"])

    @property
    def input_columns(self) -> tuple[str, ...]:
        return tuple(self.card["input_columns"])

    @property
    def n_inputs(self) -> int:
        return len(self.input_columns)

    def _mlp_forward(self) -> _Forward | None:
        steps = dict(self.pipeline.steps)
        model = steps.get("model")
        scaler = steps.get("scale")
        if model is None or scaler is None:
            return None
        physics = steps.get("physics", steps.get("kinematic"))
        mean = np.asarray(scaler.mean_, float)
        scale = np.asarray(scaler.scale_, float)
        family = self.card.get("family")
        if family == "mlp" and hasattr(model, "coefs_"):
            return _Forward(
                physics=physics,
                mean=mean,
                scale=scale,
                weights=tuple(np.asarray(w, float) for w in model.coefs_),
                biases=tuple(np.asarray(b, float) for b in model.intercepts_),
                activation=model.activation,
            )
        fitted: Any = getattr(model, "estimator_", None) if isinstance(model, ScalableSVR) else model
        linear = family == "par" or (
            family == "svr" and (isinstance(fitted, LinearSVR) or getattr(fitted, "kernel", None) == "linear")
        )
        if linear and hasattr(fitted, "coef_"):  # a linear model is a one-layer identity network
            coef = np.asarray(fitted.coef_, float).reshape(-1, 1)
            return _Forward(
                physics=physics,
                mean=mean,
                scale=scale,
                weights=(coef,),
                biases=(np.asarray(fitted.intercept_, float).reshape(1),),
                activation="identity",
            )
        return None

    # ----------------------------------------------------------- prediction
    def check_frame(self, frame: pd.DataFrame, *, source: str = "table") -> None:
        """Refuse a table whose columns lack this model's inputs, naming what is missing."""
        missing = [c for c in self.input_columns if c not in frame.columns]
        if missing:
            raise InvalidModel(
                f"{source}: lacks column(s) {', '.join(missing)} that the {self.family} model for "
                f"{self.target} was trained on (feature set {self.card['feature_set']!r}, inputs "
                f"{self.card['inputs']!r})"
            )

    def outside_training_range(self, frame: pd.DataFrame) -> np.ndarray:
        """Per row: whether it lies beyond the data the model was trained on (bool, ``(n_rows,)``).

        A row is outside when a joint's position is beyond the range of the training
        data, or its speed or acceleration beyond the largest trained on (1 % margin), or
        when it belongs to a move (``move_id``, ``t``) longer or shorter than every
        training move. Predictions there are extrapolations: the card's scores do not
        hold for them. All False for a model whose card has no ``training_range``.
        """
        covered = self.card.get("training_range")
        out = np.zeros(len(frame), dtype=bool)
        if not isinstance(covered, dict):
            return out
        n = len(covered.get("speed_max_rad_s", []))
        cols = {p: [f"{p}{i}" for i in range(1, n + 1)] for p in ("q", "dq", "ddq")}
        if all(c in frame.columns for names in cols.values() for c in names):
            q = frame[cols["q"]].to_numpy(dtype=np.float64)
            lo, hi = np.asarray(covered["q_min_rad"]), np.asarray(covered["q_max_rad"])
            pad = 0.01 * (hi - lo)
            out |= np.any((q < lo - pad) | (q > hi + pad), axis=1)
            for p, key in (("dq", "speed_max_rad_s"), ("ddq", "acceleration_max_rad_s2")):
                values = np.abs(frame[cols[p]].to_numpy(dtype=np.float64))
                out |= np.any(values > 1.01 * np.asarray(covered[key]), axis=1)
        if "move_id" in frame.columns and "t" in frame.columns and "move_duration_s" in covered:
            shortest, longest = covered["move_duration_s"]
            span = frame.groupby("move_id")["t"].transform(lambda t: t.max() - t.min()).to_numpy()
            out |= (span < 0.99 * shortest) | (span > 1.01 * longest)
        return out

    def predict(self, frame: pd.DataFrame) -> FloatArray:
        """Predict from an energy-table DataFrame (columns checked by name)."""
        self.check_frame(frame)
        return self.predict_rows(frame[list(self.input_columns)].to_numpy(dtype=np.float64))

    def predict_rows(self, X: FloatArray) -> FloatArray:
        """Predict from a float array of shape (n_rows, n_inputs) in ``input_columns`` order.

        No pandas and no validation beyond the shape: this is the optimizer's hot
        path. For an MLP it is a plain NumPy forward pass of the fitted weights (and
        for linear models — PAR, linear-kernel SVR — one matrix-vector product).
        """
        X = np.asarray(X, dtype=np.float64)
        if X.ndim != 2 or X.shape[1] != self.n_inputs:
            raise InvalidModel(
                f"X has shape {X.shape}, but the model expects (n_rows, {self.n_inputs}) inputs: "
                f"{', '.join(self.input_columns)}"
            )
        f = self._forward
        if f is not None:
            if isinstance(f.physics, KinematicFeatures):
                X = kinematic_transform(X, f.physics.index_)
            elif f.physics is not None:
                X = physics_transform(X, f.physics.index_, f.physics._robot())
            z = (X - f.mean) / f.scale
            act = _ACTIVATIONS[f.activation]
            for w, b in zip(f.weights[:-1], f.biases[:-1], strict=True):
                z = act(z @ w + b)
            out: FloatArray = (z @ f.weights[-1] + f.biases[-1])[:, 0]
            return out
        if self.family == "xgb":
            steps = dict(self.pipeline.steps)
            for name in ("physics", "kinematic"):
                if name in steps:
                    X = steps[name].transform(X)
            booster = steps["model"].get_booster()
            return np.asarray(booster.inplace_predict(X), dtype=np.float64)
        return np.asarray(self.pipeline.predict(X), dtype=np.float64)

    # ---------------------------------------------------------- persistence
    def save(self, folder: str | os.PathLike[str]) -> Path:
        """Write the model and its card into ``folder`` (created if needed)."""
        out = make_folder(folder)
        card = dict(self.card)
        card["card_version"] = CARD_VERSION
        card["input_columns_sha256"] = input_columns_sha256(self.input_columns)
        if self.family == "xgb":
            steps = dict(self.pipeline.steps)
            steps["model"].get_booster().set_attr(**{_XGB_COLUMNS_ATTR: json.dumps(list(self.input_columns))})
            with tempfile.TemporaryDirectory(prefix=".model.", dir=out) as scratch:
                tmp = Path(scratch) / "model.json"
                steps["model"].save_model(tmp)
                data = tmp.read_bytes()
            atomic_write_bytes(out / "model.json", data)
            card["file"] = "model.json"
        else:
            try:
                import skops.io as sio
            except ImportError as err:
                raise MissingDependency("skops is not installed: pip install 'joulepath[ml]'") from err
            atomic_write_bytes(out / "model.skops", sio.dumps(self.pipeline))
            card["file"] = "model.skops"
        atomic_write_text(out / "card.json", json.dumps(card, indent=2, default=str))
        return out

    @classmethod
    def load(cls, folder: str | os.PathLike[str]) -> EnergyModel:
        """Load a model folder written by :meth:`save`; never executes code from the files.

        The card and the model file are checked against each other before the model
        file reaches scikit-learn or XGBoost (see :mod:`joulepath.learn._validate`).

        Raises
        ------
        InvalidModel
            No card; a card with missing or wrong keys, or input columns in another
            order than the model was trained on; a model file outside the folder; an
            XGBoost tree out of range or cyclic; shapes that do not fit the card; or
            types outside the allowlist.
        """
        src = Path(folder)
        card_path = src / "card.json"
        if not card_path.is_file():
            raise InvalidModel(f"{src}: no card.json; is this a joulepath model folder?")
        try:
            raw = json.loads(card_path.read_bytes())
        except (json.JSONDecodeError, UnicodeDecodeError, RecursionError) as err:
            raise InvalidModel(f"{card_path}: not valid JSON ({err})") from err
        except OSError as err:
            raise InvalidModel(f"{card_path}: cannot be read ({err.strerror})") from err
        card = check_card(raw, card_path)
        if card["inputs"] == "physics" and card.get("physics_version") != PHYSICS_VERSION:
            raise InvalidModel(
                f"{card_path}: trained with physics inputs version {card.get('physics_version')}, this "
                f"joulepath computes version {PHYSICS_VERSION}; train the model again"
            )
        cols = tuple(card["input_columns"])
        if card["family"] == "xgb":
            if not isinstance(card["file"], str) or not card["file"].endswith(".json"):
                raise InvalidModel(f"{src / str(card['file'])}: an XGBoost model must be a .json booster")
            file = model_file(src, card, card_path)
            doc = check_xgboost_json(
                file, n_features=n_model_features(len(cols), card["inputs"], card_joints(cols))
            )
            trained = doc["learner"].get("attributes", {}).get(_XGB_COLUMNS_ATTR)
            if trained is not None and trained != json.dumps(list(cols)):
                raise InvalidModel(
                    f"{file}: was trained on other input columns (or another order) than {card_path} "
                    "lists; restore the card or train the model again"
                )
            from xgboost import XGBRegressor

            model = XGBRegressor()
            try:
                model.load_model(file)
            except Exception as err:  # xgboost raises its own XGBoostError
                raise InvalidModel(f"{file}: not a readable XGBoost JSON model ({err})") from err
            steps: list[tuple[str, Any]] = []
            if card["inputs"] == "physics":
                if not card.get("robot_source"):
                    raise InvalidModel(
                        f"{card_path}: a model on physics inputs must name its robot (robot_source); "
                        "train it again with `joulepath train --robot ...`"
                    )
                phys = PhysicsFeatures(robot=card["robot_source"], columns=cols)
                phys.fit(np.zeros((1, len(cols))))
                steps.append(("physics", phys))
            elif card["inputs"] == "kinematic":
                steps.append(("kinematic", KinematicFeatures(columns=cols).fit(np.zeros((1, len(cols))))))
            steps.append(("model", model))
            return cls(Pipeline(steps), card, source=src)
        if not isinstance(card["file"], str) or not card["file"].endswith(".skops"):
            raise InvalidModel(
                f"{src / str(card['file'])}: scikit-learn models are read from .skops files only"
            )
        file = model_file(src, card, card_path)
        import skops.io as sio

        try:
            untrusted = sio.get_untrusted_types(file=file)
        except Exception as err:
            raise InvalidModel(f"{file}: not a readable skops file ({err})") from err
        unknown = sorted(set(untrusted) - TRUSTED_TYPES)
        if unknown:
            raise InvalidModel(
                f"{file}: refused, it contains types outside the allowlist: {', '.join(unknown)}"
            )
        try:
            pipeline = sio.load(file, trusted=sorted(set(untrusted)))
        except Exception as err:
            raise InvalidModel(f"{file}: not a readable skops file ({err})") from err
        if not isinstance(pipeline, Pipeline):
            raise InvalidModel(f"{file}: holds a {type(pipeline).__name__}, not a Pipeline")
        check_pipeline(pipeline, card, file)
        return cls(pipeline, card, source=src)


def check_finite_predictions(model: EnergyModel, X: FloatArray) -> FloatArray:
    """Predict rows with ``model`` and refuse NaN or infinite predictions.

    Parameters
    ----------
    model : EnergyModel
    X : ndarray of shape (n_rows, n_inputs)
        Rows in ``model.input_columns`` order.

    Returns
    -------
    ndarray of shape (n_rows,)
        The predictions, all finite.

    Raises
    ------
    InvalidModel
        When any prediction is NaN or infinite (the model diverges on these inputs).
    """
    with np.errstate(all="ignore"):
        pred = model.predict_rows(X)
    bad = ~np.isfinite(pred)
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        where = f"{model.source}: " if model.source is not None else ""
        raise InvalidModel(
            f"{where}the {model.family} model for {model.target} predicts {pred[row]} for "
            f"{int(bad.sum())} of {pred.size} rows (first: row {row}); its energies cannot be "
            "trusted, train the model again or use another family"
        )
    return pred
