"""Utility of a table for learning: train on it, test on held-out real moves.

This is train-on-synthetic / test-on-real when the training table is synthetic.

Quality scores compare distributions; they do not say whether a model trained on
synthetic rows predicts real energies. :func:`utility` answers that with one
fixed, small model, the same for every training table, so that the scores of
different tables are comparable.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from joulepath._rng import check_rng, integer_seed
from joulepath.data import TARGETS, EnergyTable, check_columns
from joulepath.errors import InvalidInput
from joulepath.synth._sdv import limit_threads

HIDDEN_LAYERS = (64, 64)
MAX_ITER = 200


@dataclass(frozen=True, slots=True)
class UtilityScore:
    """Scores of the fixed MLP on the test table.

    Attributes
    ----------
    target : str
        Predicted column (``E`` by default), J.
    r2 : float
        Coefficient of determination on the test rows.
    mae : float
        Mean absolute error on the test rows, J.
    n_train, n_test : int
        Rows used.
    random_state : int
        The integer given to scikit-learn (drawn from the seed).
    converged : bool
        False when the MLP stopped at ``max_iter`` before early stopping ended it.
    """

    target: str
    r2: float
    mae: float
    n_train: int
    n_test: int
    random_state: int
    converged: bool


def make_model(random_state: int) -> Any:
    """The fixed pipeline: ``StandardScaler`` + ``MLPRegressor``.

    The MLP has hidden layers (64, 64), ``early_stopping=True`` and ``max_iter=200``.
    """
    try:
        from sklearn.neural_network import MLPRegressor
        from sklearn.pipeline import make_pipeline
        from sklearn.preprocessing import StandardScaler
    except ImportError as err:
        from joulepath.errors import MissingDependency

        raise MissingDependency(
            f"utility needs scikit-learn ({err}); install the extra with: pip install 'joulepath[ml]'"
        ) from err
    return make_pipeline(
        StandardScaler(),
        MLPRegressor(
            hidden_layer_sizes=HIDDEN_LAYERS,
            early_stopping=True,
            max_iter=MAX_ITER,
            random_state=random_state,
        ),
    )


def utility(
    train: EnergyTable,
    test: EnergyTable,
    *,
    seed: int | np.random.Generator | None = None,
    target: str = "E",
    n_threads: int = 1,
) -> UtilityScore:
    """Train the fixed MLP on ``train``'s features and score it on ``test``.

    Parameters
    ----------
    train : EnergyTable
        Synthetic or real training rows.
    test : EnergyTable
        Held-out real rows (other moves than any training table saw), same feature set.
    seed : int, Generator or None
        Resolved once; one integer drawn from it seeds the MLP.
    target : str
        One of ``E1..E6, E``.
    n_threads : int
        BLAS threads while training and predicting (default 1: the MLP is small,
        and more threads can be much slower on machines with few or shared cores).

    Returns
    -------
    UtilityScore

    Raises
    ------
    InvalidInput
        Tables of different feature sets, an unknown target, or fewer than 20
        training rows (early stopping holds out 10 % of them).
    """
    for name, table in (("train", train), ("test", test)):
        if not isinstance(table, EnergyTable):
            raise InvalidInput(f"utility: {name} must be an EnergyTable, got {type(table).__name__}")
        check_columns(table.frame, table.feature_set, source=f"utility ({name})")
    if train.feature_set != test.feature_set:
        raise InvalidInput(
            f"utility: train has feature set {train.feature_set!r} and test {test.feature_set!r}; "
            "they must match"
        )
    if isinstance(n_threads, bool) or not isinstance(n_threads, int) or n_threads < 1:
        raise InvalidInput(f"utility: n_threads must be a positive integer, got {n_threads!r}")
    if target not in TARGETS:
        raise InvalidInput(f"utility: unknown target {target!r}; choose one of {', '.join(TARGETS)}")
    if len(train.frame) < 20 or len(test.frame) < 1:
        raise InvalidInput(
            f"utility: needs at least 20 training rows and 1 test row, got {len(train.frame)} and "
            f"{len(test.frame)}"
        )
    from sklearn.exceptions import ConvergenceWarning
    from sklearn.metrics import mean_absolute_error, r2_score

    random_state = integer_seed(check_rng(seed))
    features = list(train.features)
    model = make_model(random_state)
    x_train = train.frame[features].to_numpy(dtype=float)
    y_train = train.frame[target].to_numpy(dtype=float)
    with limit_threads(n_threads):
        with warnings.catch_warnings():
            # reaching max_iter is reported in UtilityScore.converged instead
            warnings.filterwarnings("ignore", category=ConvergenceWarning)
            model.fit(x_train, y_train)
        pred = model.predict(test.frame[features].to_numpy(dtype=float))
    converged = int(model[-1].n_iter_) < MAX_ITER
    y_test = test.frame[target].to_numpy(dtype=float)
    return UtilityScore(
        target=target,
        r2=float(r2_score(y_test, pred)),
        mae=float(mean_absolute_error(y_test, pred)),
        n_train=len(y_train),
        n_test=len(y_test),
        random_state=random_state,
        converged=converged,
    )


__all__ = ["HIDDEN_LAYERS", "MAX_ITER", "UtilityScore", "make_model", "utility"]
