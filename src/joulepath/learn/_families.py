"""The four model families of the thesis (§2.2) and joulepath's ``bases``; pipelines and grids.

The thesis' grids are its Tables 2.2–2.5. ``bases`` (:class:`~joulepath.learn.JointEnergyBases`)
is a least-squares model of each joint's energy on a few energy bases of its motion; it
is not in the thesis, and its pipeline is [PhysicsFeatures or KinematicFeatures →] model
(no scaling: it scales its own bases).

SVR is :class:`~joulepath.learn.ScalableSVR`: the linear kernel is fitted with
liblinear (``LinearSVR``, squared epsilon-insensitive loss) and the other kernels on at most
:data:`~joulepath.learn.KERNEL_SVR_MAX_ROWS` sampled rows, so the thesis grid runs
on the thesis' table sizes.

Every family is a scikit-learn Pipeline: [PhysicsFeatures or KinematicFeatures →] StandardScaler →
estimator (XGBoost trees need no scaling and get none, so the fitted booster can be
saved in XGBoost's own JSON format). Grid keys are written ``model__param``.

``PassiveAggressiveRegressor`` is deprecated in scikit-learn 1.8 and removed in
1.10; where it is deprecated or missing we use its documented equivalent
``SGDRegressor(loss="epsilon_insensitive", penalty=None, learning_rate="pa1"|"pa2",
eta0=C)``: the thesis' ``loss`` values ``epsilon_insensitive`` /
``squared_epsilon_insensitive`` (PA-I / PA-II) become ``learning_rate`` ``pa1`` /
``pa2``, and ``C`` becomes ``eta0``. :data:`SUBSTITUTIONS` records it for reports.
"""

from __future__ import annotations

from typing import Any

import sklearn
from sklearn.linear_model import SGDRegressor
from sklearn.neural_network import MLPRegressor
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import StandardScaler

from joulepath.errors import InvalidInput, MissingDependency
from joulepath.learn._bases import JointEnergyBases
from joulepath.learn._features import KinematicFeatures, PhysicsFeatures
from joulepath.learn._svr import ScalableSVR

FAMILIES = ("mlp", "svr", "par", "xgb", "bases")
GRIDS = ("thesis", "quick")

SUBSTITUTIONS = {
    "par": (
        f"PassiveAggressiveRegressor is deprecated in scikit-learn {sklearn.__version__}; "
        "replaced by its documented equivalent SGDRegressor(loss='epsilon_insensitive', "
        "penalty=None, learning_rate='pa1'|'pa2', eta0=C): thesis loss epsilon_insensitive -> pa1, "
        "squared_epsilon_insensitive -> pa2, C -> eta0"
    ),
    "svr": (
        "SVR is joulepath's ScalableSVR: the linear kernel is fitted with LinearSVR on the squared "
        "epsilon-insensitive loss (primal liblinear; libsvm's linear SVR and liblinear's dual solver "
        "take minutes to hours on tens of thousands of rows), the other kernels with SVR on at most "
        "KERNEL_SVR_MAX_ROWS = 5,000 randomly sampled rows"
    ),
}

_HIDDEN = [
    (10,),
    (50,),
    (100,),
    (10, 10),
    (50, 50),
    (100, 100),
    (10, 10, 10),
    (50, 50, 50),
    (100, 100, 100),
    (10, 10, 10, 10),
    (50, 50, 50, 50),
    (100, 100, 100, 100),
]

THESIS_GRIDS: dict[str, dict[str, list[Any]]] = {
    "mlp": {  # Table 2.2
        "model__hidden_layer_sizes": _HIDDEN,
        "model__activation": ["identity", "logistic", "tanh", "relu"],
        "model__solver": ["lbfgs", "adam"],
        "model__alpha": [0.0001, 0.001, 0.01, 0.1],
        "model__learning_rate": ["constant", "adaptive", "invscaling"],
        "model__learning_rate_init": [0.01, 0.1, 1.0],
    },
    "svr": {  # Table 2.3
        "model__kernel": ["linear", "poly", "rbf", "sigmoid"],
        "model__degree": [2, 3, 4],
        "model__gamma": ["scale", "auto"],
        "model__C": [0.1, 0.5, 1.0, 10.0],
        "model__epsilon": [0.1, 0.2, 0.5, 1.0],
    },
    "par": {  # Table 2.4 (through the SGDRegressor equivalent)
        "model__eta0": [0.1, 0.5, 1.0, 10.0],
        "model__fit_intercept": [True, False],
        "model__tol": [1e-3, 1e-4, 1e-5],
        "model__learning_rate": ["pa1", "pa2"],
        "model__epsilon": [0.1, 0.2, 0.5, 1.0],
    },
    "xgb": {  # Table 2.5
        "model__n_estimators": [10, 50, 100],
        "model__max_depth": [3, 4, 5, 6, 7],
        "model__learning_rate": [0.01, 0.1, 1.0],
        "model__subsample": [0.5, 0.75, 1.0],
        "model__colsample_bytree": [0.5, 0.75, 1.0],
        "model__colsample_bylevel": [0.5, 0.75, 1.0],
        "model__colsample_bynode": [0.5, 0.75, 1.0],
        "model__reg_alpha": [0.0, 0.1, 0.5, 1.0],
        "model__reg_lambda": [0.0, 0.1, 0.5, 1.0],
    },
    "bases": {"model__alpha": [0.0, 1e-4, 1e-2]},  # not in the thesis: the quick grid
}

QUICK_GRIDS: dict[str, dict[str, list[Any]]] = {
    "mlp": {
        "model__hidden_layer_sizes": [(50,)],
        "model__activation": ["identity", "relu"],
        "model__alpha": [0.1],
    },
    "svr": {"model__kernel": ["linear"], "model__C": [0.1, 1.0], "model__epsilon": [0.005]},
    "par": {"model__eta0": [0.01, 0.1], "model__learning_rate": ["pa1", "pa2"], "model__epsilon": [0.005]},
    "xgb": {"model__n_estimators": [500], "model__max_depth": [2, 3], "model__learning_rate": [0.1]},
    "bases": {"model__alpha": [0.0, 1e-4, 1e-2]},
}
"""Small grids for tests and the demo (chosen on simulated lab data, not from the thesis)."""


def _estimator(family: str, seed: int, inputs: str = "thesis", columns: tuple[str, ...] | None = None) -> Any:
    if family == "bases":
        return JointEnergyBases(columns=columns, inputs=inputs)
    if family == "mlp":
        return MLPRegressor(max_iter=500, early_stopping=True, random_state=seed)
    if family == "svr":
        return ScalableSVR(random_state=seed)
    if family == "par":
        return SGDRegressor(
            loss="epsilon_insensitive",
            penalty=None,
            learning_rate="pa1",
            eta0=1.0,
            max_iter=1000,
            random_state=seed,
        )
    if family == "xgb":
        try:
            from xgboost import XGBRegressor
        except ImportError as err:
            raise MissingDependency("XGBoost is not installed: pip install 'joulepath[ml]'") from err
        return XGBRegressor(random_state=seed, n_jobs=1, tree_method="hist")
    raise InvalidInput(f"unknown model family {family!r}; use one of {', '.join(FAMILIES)}")


def make_pipeline(
    family: str,
    *,
    seed: int,
    inputs: str = "physics",
    columns: tuple[str, ...] | None = None,
    robot: str | None = None,
) -> Pipeline:
    """The family's pipeline with its default hyperparameters.

    ``robot`` (the robot of the data) is required for ``inputs="physics"``.
    """
    steps: list[tuple[str, Any]] = []
    if inputs == "physics":
        if robot is None:
            raise InvalidInput("physics inputs need the robot of the data; give robot=<name or path>")
        steps.append(("physics", PhysicsFeatures(robot=robot, columns=columns)))
    elif inputs == "kinematic":
        steps.append(("kinematic", KinematicFeatures(columns=columns)))
    elif inputs != "thesis":
        raise InvalidInput(f"inputs must be 'thesis', 'physics' or 'kinematic', got {inputs!r}")
    if family not in ("xgb", "bases"):
        steps.append(("scale", StandardScaler()))
    steps.append(("model", _estimator(family, seed, inputs, columns)))
    return Pipeline(steps)


def grid_for(family: str, grid: str) -> dict[str, list[Any]]:
    """The hyperparameter grid (``thesis`` or ``quick``) of a family."""
    if grid not in GRIDS:
        raise InvalidInput(f"grid must be one of {GRIDS}, got {grid!r}")
    if family not in FAMILIES:
        raise InvalidInput(f"unknown model family {family!r}; use one of {', '.join(FAMILIES)}")
    return (THESIS_GRIDS if grid == "thesis" else QUICK_GRIDS)[family]
