"""The one module that talks to SDV and SDMetrics (imported lazily, inside functions).

Everything SDV-specific lives here: explicit metadata, the four single-table
synthesizers, seeding, saving and loading, and SDMetrics' quality report. The
rest of :mod:`joulepath.synth` sees plain DataFrames, integers and floats.

Seeding
-------
SDV has no public seed. Its synthesizers draw from NumPy's legacy global
generator and from torch's global generator while they fit, and sample from a
generator of their own that SDV resets to a fixed seed after ``fit``
(``reset_sampling()`` rewinds it). :func:`fit` and :func:`sample` therefore take
a plain integer (the caller draws it from its ``numpy.random.Generator``) and,
for the duration of the call only:

* seed NumPy's global generator and torch's global generator with it, and
  restore both generators' previous states afterwards (nothing outside the call
  sees a changed global state);
* run torch with ``n_threads`` intra-op threads (default 1), and limit the
  BLAS/OpenMP pools to as many (:func:`limit_threads`), restoring both
  afterwards: one thread makes CPU training bit-for-bit repeatable, and on
  these small networks it is also faster than several;
* in :func:`sample`, rewind SDV's sampling state (``reset_sampling()``) and then
  seed the model's own sampling generator with the integer. The latter uses
  ``BaseSingleTableSynthesizer._set_random_state``, a private SDV method (present
  in SDV 1.x and 2.x) because SDV offers no public way to seed sampling.

The same fitted model and the same integer therefore give the same rows.

Pickle
------
SDV saves a synthesizer with ``cloudpickle``; loading such a file executes code
stored in it. :func:`load_model` only unpickles bytes whose SHA-256 the caller has
already checked against the value recorded when the file was written (see
:meth:`joulepath.synth.Synthesizer.load`). Only load files you wrote yourself.
"""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator, Sequence
from types import ModuleType
from typing import Any

import pandas as pd

from joulepath.errors import MissingDependency

TABLE_NAME = "energy"
"""Name of the single table in SDV's metadata and in SDMetrics' reports."""

METHODS: tuple[str, ...] = ("copula", "copulagan", "ctgan", "tvae")
"""Synthesizer names: GaussianCopula, CopulaGAN, CTGAN and TVAE of ``sdv.single_table``."""

NEURAL_METHODS: tuple[str, ...] = ("copulagan", "ctgan", "tvae")
"""Methods that train a neural network (they use ``epochs`` and ``batch_size``)."""

PAC = 10
"""CTGAN's and CopulaGAN's discriminator packs this many rows; the batch size must be a multiple."""

_CLASSES = {
    "copula": "GaussianCopulaSynthesizer",
    "copulagan": "CopulaGANSynthesizer",
    "ctgan": "CTGANSynthesizer",
    "tvae": "TVAESynthesizer",
}

_EXTRA = "pip install 'joulepath[synth]'"


def _require(module: str) -> ModuleType:
    """Import an optional module or raise MissingDependency naming the extra."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as err:
        raise MissingDependency(
            f"synthetic data needs the optional package {module.split('.')[0]!r} ({err}); "
            f"install the extra with: {_EXTRA}"
        ) from err


def versions() -> dict[str, str]:
    """Installed versions of sdv, sdmetrics and torch (recorded with saved models)."""
    from importlib.metadata import PackageNotFoundError, version

    out = {}
    for name in ("sdv", "sdmetrics", "torch"):
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "not installed"
    return out


def metadata_dict(columns: Sequence[str]) -> dict[str, Any]:
    """SDV/SDMetrics metadata (spec V2) declaring every column numerical.

    Examples
    --------
    >>> metadata_dict(["q1", "E"])["tables"]["energy"]["columns"]["E"]
    {'sdtype': 'numerical'}
    """
    return {
        "METADATA_SPEC_VERSION": "V2",
        "tables": {TABLE_NAME: {"columns": {c: {"sdtype": "numerical"} for c in columns}}},
        "relationships": [],
    }


def make_model(
    method: str,
    columns: Sequence[str],
    *,
    epochs: int,
    batch_size: int,
    verbose: bool,
    enforce_min_max_values: bool,
) -> Any:
    """A new, unfitted SDV single-table synthesizer with explicit metadata.

    Values are not rounded (``enforce_rounding=False``: the columns are
    measurements, not counts); ``enforce_min_max_values`` clips samples to the
    range seen in fit. The neural methods run on the CPU (``enable_gpu=False``).
    ``epochs``, ``batch_size`` and ``verbose`` (SDV's per-epoch progress bar) are
    ignored by ``copula``.
    """
    metadata_mod = _require("sdv.metadata")
    single_table = _require("sdv.single_table")
    installed = versions()["sdv"]
    if int(installed.split(".")[0]) < 2:
        raise MissingDependency(
            f"joulepath.synth needs sdv >= 2.0 (its synthesizers take and return dicts of tables), "
            f"but sdv {installed} is installed; upgrade with: pip install -U 'sdv>=2.0'"
        )
    metadata = metadata_mod.Metadata.load_from_dict(metadata_dict(columns))
    cls = getattr(single_table, _CLASSES[method])
    kwargs: dict[str, Any] = {
        "enforce_min_max_values": enforce_min_max_values,
        "enforce_rounding": False,
    }
    if method in NEURAL_METHODS:
        kwargs.update(epochs=epochs, batch_size=batch_size, verbose=verbose, enable_gpu=False)
    return cls(metadata, **kwargs)


def limit_threads(n_threads: int) -> contextlib.ExitStack:
    """Limit BLAS and OpenMP thread pools (threadpoolctl) for a block; with 1, run joblib in-process.

    The models here are small; extra threads rarely help them, cost a lot on
    machines with few or shared cores, and can change floating-point results.
    threadpoolctl and joblib are scikit-learn dependencies; without them this
    does nothing.
    """
    stack = contextlib.ExitStack()
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        pass
    else:
        stack.enter_context(threadpool_limits(limits=n_threads))
    if n_threads == 1:
        try:
            from joblib import parallel_config
        except ImportError:
            pass
        else:
            # CTGAN's data transformer fans columns out to worker processes (joblib, all
            # cores); starting them costs seconds and gains nothing on small tables
            stack.enter_context(parallel_config(backend="sequential"))
    return stack


@contextlib.contextmanager
def seeded(seed: int, *, n_threads: int = 1) -> Iterator[None]:
    """Seed NumPy's and torch's global generators and set torch's thread count, then restore all.

    SDV, CTGAN, RDT and copulas draw from these global generators; this context
    is the only place joulepath touches them, and it puts back the previous
    states on exit (also when the body raises).
    """
    import numpy as np

    torch = _require("torch")
    # SDV and its libraries draw from NumPy's legacy global generator; we seed it here
    # and put its state back afterwards (the only use of the legacy API in joulepath)
    np_state = np.random.get_state()  # noqa: NPY002
    torch_state = torch.get_rng_state()
    threads = torch.get_num_threads()
    np.random.set_state(np.random.RandomState(seed).get_state())  # noqa: NPY002
    torch.manual_seed(seed)
    torch.set_num_threads(n_threads)
    try:
        with limit_threads(n_threads):
            yield
    finally:
        torch.set_num_threads(threads)
        torch.set_rng_state(torch_state)
        np.random.set_state(np_state)  # noqa: NPY002


def fit(model: Any, frame: pd.DataFrame, *, seed: int, n_threads: int = 1) -> None:
    """Fit ``model`` on ``frame`` (its columns must be the model's) under :func:`seeded`."""
    with seeded(seed, n_threads=n_threads):
        model.fit({TABLE_NAME: frame})


def sample(model: Any, n_rows: int, *, seed: int, n_threads: int = 1) -> pd.DataFrame:
    """``n_rows`` rows from a fitted ``model``; the same model and ``seed`` give the same rows."""
    with seeded(seed, n_threads=n_threads):
        model.reset_sampling()
        model._set_random_state(seed)  # private SDV API: SDV has no public sampling seed
        out = model.sample(n_rows)
    frame = out[TABLE_NAME] if isinstance(out, dict) else out
    return frame.reset_index(drop=True)


def is_fitted(model: Any) -> bool:
    """Whether an SDV synthesizer has been fitted."""
    return bool(getattr(model, "_fitted", False))


def model_bytes(model: Any) -> bytes:
    """The synthesizer in SDV's own save format (cloudpickle of the synthesizer object)."""
    cloudpickle = _require("cloudpickle")
    data: bytes = cloudpickle.dumps(model)
    return data


def load_model(data: bytes) -> Any:
    """Unpickle a synthesizer from ``data``.

    Executes the pickle: call it only on bytes whose SHA-256 you have checked
    against the value recorded when you saved them.
    """
    cloudpickle = _require("cloudpickle")
    single_table = _require("sdv.single_table")
    obj = cloudpickle.loads(data)
    if not isinstance(obj, single_table.base.BaseSingleTableSynthesizer):
        raise TypeError(f"expected an SDV single-table synthesizer, got {type(obj).__name__}")
    return obj


def quality_scores(
    real: pd.DataFrame,
    synthetic: pd.DataFrame,
    columns: Sequence[str],
    *,
    correlation_threshold: float = 0.0,
) -> tuple[float, float, float, pd.DataFrame]:
    """SDMetrics' quality report (``sdmetrics.reports.QualityReport``) on ``columns``.

    ``correlation_threshold`` is SDMetrics' ``real_correlation_threshold``: column
    pairs whose real Pearson correlation is at most this in absolute value are
    left out of Column Pair Trends (recent SDMetrics default to 0.5; 0 scores
    every pair, as the SDMetrics the thesis used did).

    Returns
    -------
    column_shapes, column_pair_trends, overall : float
        Scores in [0, 1]; ``overall`` is the mean of the two properties. Column
        Pair Trends is NaN when no pair passes the threshold.
    details : DataFrame
        SDMetrics' per-column Column Shapes scores (columns ``Column``, ``Metric``, ``Score``).
    """
    reports = _require("sdmetrics.reports")
    cols = list(columns)
    report = reports.QualityReport()
    report.real_correlation_threshold = correlation_threshold
    with warnings.catch_warnings():
        # scipy warns when a column of one of the tables is constant (its correlation is
        # undefined); SDMetrics then scores the pair from the values it can compute
        warnings.filterwarnings("ignore", message=".*constant.*", category=RuntimeWarning)
        report.generate(
            {TABLE_NAME: real[cols]}, {TABLE_NAME: synthetic[cols]}, metadata_dict(cols), verbose=False
        )
    props = report.get_properties().set_index("Property")["Score"]
    shapes = float(props["Column Shapes"])
    pairs = float(props["Column Pair Trends"]) if len(cols) > 1 else float("nan")
    details = report.get_details("Column Shapes")
    return shapes, pairs, float(report.get_score()), details


__all__ = [
    "METHODS",
    "NEURAL_METHODS",
    "PAC",
    "TABLE_NAME",
    "fit",
    "is_fitted",
    "limit_threads",
    "load_model",
    "make_model",
    "metadata_dict",
    "model_bytes",
    "quality_scores",
    "sample",
    "seeded",
    "versions",
]
