"""Grow an energy table with an SDV synthesizer: config, adapter, saving and loading.

What is modelled
----------------
The synthesizer learns the joint distribution of the feature columns, the
per-joint energies ``E1..E6`` and the sample length ``dt`` of the real table.
The other columns are derived after sampling so that the output keeps the
energy-table schema (the same columns, in order, with the same dtypes):

* ``E`` is the sum ``E1 + ... + E6`` (its definition), not a separate model
  output, so the targets of a synthetic row always add up;
* ``move_id`` is not a quantity and is not modelled. Synthetic rows are
  independent draws, so they form no trajectories; they are numbered in
  blocks of ``rows_per_move`` consecutive rows (default: the real table's mean
  rows per move), giving pseudo-moves of realistic size for group-wise splits;
* ``t`` is not modelled (a log clock says nothing about a single row); it is the
  running sum of the synthetic ``dt`` from 0, a synthetic clock.

Seeds
-----
:class:`Synthesizer` resolves ``SynthConfig.seed`` once, in :meth:`Synthesizer.fit`,
into a ``numpy.random.Generator`` and draws from it one integer for fitting and
one for each :meth:`Synthesizer.sample` call; :mod:`joulepath.synth._sdv` turns
those integers into SDV's, NumPy's and torch's states (see its docstring). The
same seed and the same calls give the same tables; the integers are recorded in
the output table's ``sources``.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Self

import numpy as np
import pandas as pd

from joulepath._io import atomic_write_bytes, atomic_write_text
from joulepath._rng import check_rng, integer_seed
from joulepath.data import EnergyTable, check_columns, table_columns
from joulepath.errors import InvalidInput, InvalidLog
from joulepath.synth import _sdv

if TYPE_CHECKING:
    from joulepath.dynamics import Robot

MODEL_FORMAT = "joulepath-synthesizer"
FORMAT_VERSION = 1
MIN_ROWS = 10
"""Fewest rows a table must have to be fitted."""


class NotFittedError(InvalidInput):
    """:meth:`Synthesizer.sample` or :meth:`Synthesizer.save` was called before :meth:`Synthesizer.fit`."""


class UntrustedModelFile(InvalidInput):
    """A synthesizer file whose SHA-256 does not match its sidecar, or that has no valid sidecar."""


@dataclass(frozen=True, slots=True, kw_only=True)
class SynthConfig:
    """Settings of a synthesizer.

    Parameters
    ----------
    method : {"copula", "copulagan", "ctgan", "tvae"}
        SDV's GaussianCopula, CopulaGAN, CTGAN or TVAE single-table synthesizer.
    epochs : int
        Training epochs of the neural methods (SDV's default 300; ignored by ``copula``).
    batch_size : int
        Rows per training batch of the neural methods (SDV's default 500). Even; for
        ``ctgan`` and ``copulagan`` a multiple of 10 (their discriminator packs 10 rows).
    seed : int or None
        Seed of the fit and of the samples; None draws fresh entropy.
    n_threads : int
        torch threads while fitting and sampling; 1 (default) is bit-for-bit repeatable.
    rows_per_move : int or None
        Size of the synthetic ``move_id`` blocks; None: the real table's mean rows per move.
    enforce_min_max : bool
        Clip samples to each column's range in the real table (SDV's ``enforce_min_max_values``).
    verbose : bool
        Show SDV's per-epoch progress bar (stderr) while a neural method trains.

    Raises
    ------
    InvalidInput
        For an unknown method or a value out of range.

    Examples
    --------
    >>> SynthConfig(method="tvae", epochs=5, seed=1).batch_size
    500
    >>> SynthConfig(method="gan")
    Traceback (most recent call last):
    ...
    joulepath.errors.InvalidInput: unknown method 'gan'; choose one of copula, copulagan, ctgan, tvae
    """

    method: str = "tvae"
    epochs: int = 300
    batch_size: int = 500
    seed: int | None = None
    n_threads: int = 1
    rows_per_move: int | None = None
    enforce_min_max: bool = True
    verbose: bool = False

    def __post_init__(self) -> None:
        if self.method not in _sdv.METHODS:
            raise InvalidInput(f"unknown method {self.method!r}; choose one of {', '.join(_sdv.METHODS)}")
        for name in ("epochs", "batch_size", "n_threads"):
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or value < 1:
                raise InvalidInput(f"{name} must be a positive integer, got {value!r}")
        if self.batch_size % 2:
            raise InvalidInput(f"batch_size must be even, got {self.batch_size}")
        if self.method in ("ctgan", "copulagan") and self.batch_size % _sdv.PAC:
            raise InvalidInput(
                f"batch_size for {self.method} must be a multiple of {_sdv.PAC} "
                f"(its discriminator packs {_sdv.PAC} rows), got {self.batch_size}; "
                f"try {max(_sdv.PAC, round(self.batch_size / _sdv.PAC) * _sdv.PAC)}"
            )
        if self.rows_per_move is not None and (
            not isinstance(self.rows_per_move, int) or self.rows_per_move < 1
        ):
            raise InvalidInput(
                f"rows_per_move must be a positive integer or None, got {self.rows_per_move!r}"
            )
        if self.seed is not None and (not isinstance(self.seed, int) or isinstance(self.seed, bool)):
            raise InvalidInput(f"seed must be an integer or None, got {self.seed!r}")


def model_columns(feature_set: str) -> tuple[str, ...]:
    """Columns the synthesizer learns: the features, ``E1..E6`` and ``dt`` (not move_id, t, E).

    Examples
    --------
    >>> cols = model_columns("full40")
    >>> len(cols), cols[0], cols[-2:]
    (47, 'q1', ('E6', 'dt'))
    """
    return tuple(c for c in table_columns(feature_set) if c not in ("move_id", "t", "E"))


def _check_table(table: EnergyTable, *, where: str) -> None:
    if not isinstance(table, EnergyTable):
        raise InvalidInput(
            f"{where} expects an EnergyTable (joulepath.data.load_table), got {type(table).__name__}"
        )
    check_columns(table.frame, table.feature_set, source=where)
    if len(table.frame) < MIN_ROWS:
        raise InvalidLog(f"{where}: the table has {len(table.frame)} rows; at least {MIN_ROWS} are needed")
    values = table.frame[list(model_columns(table.feature_set))]
    bad = [c for c in values.columns if not np.isfinite(values[c].to_numpy(dtype=float)).all()]
    if bad:
        raise InvalidLog(
            f"{where}: column(s) {', '.join(bad)} hold NaN or infinite values; "
            "drop those rows (e.g. frame.dropna()) before fitting"
        )


def finish_frame(
    sampled: pd.DataFrame, *, feature_set: str, rows_per_move: int, first_move_id: int = 0
) -> pd.DataFrame:
    """Add the derived columns to sampled model columns and put the table in schema order.

    Parameters
    ----------
    sampled : DataFrame
        The model columns (:func:`model_columns`), one row per synthetic sample.
    feature_set : str
    rows_per_move : int
        Size of the ``move_id`` blocks.
    first_move_id : int
        ``move_id`` of the first block.

    Returns
    -------
    DataFrame with the columns of ``table_columns(feature_set)``: ``move_id`` int64, the rest float64.
    """
    n = len(sampled)
    out = sampled.astype("float64").reset_index(drop=True)
    energies = out[[f"E{i}" for i in range(1, 7)]].to_numpy()
    out["E"] = energies.sum(axis=1)
    dt = out["dt"].to_numpy()
    out["t"] = np.concatenate([[0.0], np.cumsum(dt)[:-1]]) if n else np.zeros(0)
    out["move_id"] = (np.arange(n, dtype=np.int64) // rows_per_move + first_move_id).astype(np.int64)
    return out[list(table_columns(feature_set))]


def _seed_text(seed: int | None) -> str:
    """The user's seed as progress messages show it (the integers SDV gets are derived from it)."""
    return "no seed: fresh entropy" if seed is None else f"seed {seed}"


class Synthesizer:
    """An SDV synthesizer that learns an energy table and samples new ones.

    Parameters
    ----------
    config : SynthConfig, optional
        Method, epochs, batch size and seed (default ``SynthConfig()``: TVAE, 300 epochs).

    Examples
    --------
    >>> synth = Synthesizer(SynthConfig(method="copula", seed=0))
    >>> synth.is_fitted
    False
    """

    def __init__(self, config: SynthConfig | None = None) -> None:
        self._config = config if config is not None else SynthConfig()
        self._model: Any = None
        self._rng: np.random.Generator | None = None
        self._info: dict[str, Any] = {}

    @property
    def config(self) -> SynthConfig:
        """The settings this synthesizer was made with."""
        return self._config

    @property
    def is_fitted(self) -> bool:
        """Whether :meth:`fit` (or :meth:`load`) has given this synthesizer a model."""
        return self._model is not None

    @property
    def info(self) -> dict[str, Any]:
        """What the fit saw: feature set, robot, rows, moves, fingerprint, fit seed, versions."""
        return dict(self._info)

    def fit(self, table: EnergyTable, *, progress: Callable[[str], None] | None = None) -> Self:
        """Learn the distribution of ``table``'s model columns (see :func:`model_columns`).

        Parameters
        ----------
        table : EnergyTable
            The real table, e.g. the micro set.
        progress : callable, optional
            Called with a short message when fitting starts and ends.

        Returns
        -------
        self

        Raises
        ------
        InvalidInput
            ``table`` is not an EnergyTable.
        InvalidLog
            Columns that do not match the feature set, fewer than 10 rows, or NaN/infinite values.
        MissingDependency
            SDV is not installed.
        """
        _check_table(table, where="Synthesizer.fit")
        cfg = self._config
        rng = check_rng(cfg.seed)
        fit_seed = integer_seed(rng)
        columns = model_columns(table.feature_set)
        frame = table.frame[list(columns)].astype("float64")
        model = _sdv.make_model(
            cfg.method,
            columns,
            epochs=cfg.epochs,
            batch_size=cfg.batch_size,
            verbose=cfg.verbose,
            enforce_min_max_values=cfg.enforce_min_max,
        )
        if progress:
            progress(
                f"fitting {cfg.method} on {len(frame):,} rows x {len(columns)} columns "
                f"({_seed_text(cfg.seed)}; SDV fit seed {fit_seed} derived from it)"
            )
        _sdv.fit(model, frame, seed=fit_seed, n_threads=cfg.n_threads)
        n_moves = max(table.n_moves, 1)
        self._model = model
        self._rng = rng
        self._info = {
            "feature_set": table.feature_set,
            "robot": table.robot,
            "n_rows": len(table.frame),
            "n_moves": table.n_moves,
            "rows_per_move": cfg.rows_per_move or max(1, round(len(table.frame) / n_moves)),
            "fingerprint": table.fingerprint(),
            "fit_seed": fit_seed,
            "versions": _sdv.versions(),
        }
        if progress:
            progress(f"fitted {cfg.method}")
        return self

    def _fitted_state(self, what: str) -> tuple[Any, np.random.Generator]:
        if self._model is None or self._rng is None:
            raise NotFittedError(
                f"this Synthesizer is not fitted yet; call fit(table) (or Synthesizer.load(path)) "
                f"before {what}"
            )
        return self._model, self._rng

    def sample(self, n_rows: int, *, progress: Callable[[str], None] | None = None) -> EnergyTable:
        """Draw ``n_rows`` synthetic rows as an energy table of the fitted feature set.

        Each call draws a new sampling seed from the synthesizer's generator, so two
        calls give different rows and a refit (or a loaded copy) with the same seed
        repeats the same sequence of tables.

        Parameters
        ----------
        n_rows : int
            Number of rows, >= 1.
        progress : callable, optional
            Called with a short message when sampling starts.

        Returns
        -------
        EnergyTable
            The energy-table schema (columns and dtypes) of the real table;
            ``sources`` records the method, seeds and the real table's fingerprint.

        Raises
        ------
        NotFittedError
            Before :meth:`fit`.
        InvalidInput
            ``n_rows`` is not a positive integer.
        """
        model, rng = self._fitted_state("sample()")
        if isinstance(n_rows, bool) or not isinstance(n_rows, (int, np.integer)) or n_rows < 1:
            raise InvalidInput(f"n_rows must be a positive integer, got {n_rows!r}")
        cfg = self._config
        seed = integer_seed(rng)
        if progress:
            progress(
                f"sampling {int(n_rows):,} rows from {cfg.method} "
                f"({_seed_text(cfg.seed)}; SDV sampling seed {seed} derived from it)"
            )
        raw = _sdv.sample(model, int(n_rows), seed=seed, n_threads=cfg.n_threads)
        info = self._info
        frame = finish_frame(raw, feature_set=info["feature_set"], rows_per_move=info["rows_per_move"])
        source = {
            "synthetic": cfg.method,
            "rows": len(frame),
            "config": asdict(cfg),
            "fit_seed": info["fit_seed"],
            "sample_seed": seed,
            "real_fingerprint": info["fingerprint"],
            "real_rows": info["n_rows"],
            "versions": info["versions"],
        }
        return EnergyTable(
            frame=frame, feature_set=info["feature_set"], robot=info["robot"], sources=(source,)
        )

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the fitted synthesizer to ``path`` and a JSON sidecar ``<path>.json``.

        The model file is SDV's own save format: a (cloud)pickle of the SDV
        synthesizer. The sidecar holds its SHA-256, the config, what the fit saw
        and the state of the sampling generator, so a loaded copy continues
        exactly where this one stands. Both files are written atomically.

        Returns
        -------
        Path
            ``path``.

        Raises
        ------
        NotFittedError
            Before :meth:`fit`.
        """
        model, rng = self._fitted_state("save()")
        p = Path(path)
        data = _sdv.model_bytes(model)
        sidecar = {
            "format": MODEL_FORMAT,
            "format_version": FORMAT_VERSION,
            "model_file": p.name,
            "sha256": hashlib.sha256(data).hexdigest(),
            "config": asdict(self._config),
            "info": self._info,
            "rng_state": rng.bit_generator.state,
        }
        atomic_write_bytes(p, data)
        atomic_write_text(sidecar_path(p), json.dumps(sidecar, indent=2) + "\n")
        return p

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Synthesizer:
        """Load a synthesizer written by :meth:`save`, after checking its SHA-256.

        The model file is a pickle, and unpickling runs code stored in it: only load
        files you wrote. The bytes are unpickled only if their SHA-256 equals the
        one recorded in the sidecar ``<path>.json``, and only if the installed SDV
        is the version that wrote them.

        Raises
        ------
        UntrustedModelFile
            No sidecar, a sidecar of another format, or a model file whose SHA-256
            differs from the recorded one (changed or replaced since it was saved).
        InvalidInput
            The file was written with another SDV version.
        """
        p = Path(path)
        side = sidecar_path(p)
        try:
            data = p.read_bytes()
        except OSError as err:
            raise InvalidInput(f"{p}: cannot read the synthesizer file ({err})") from err
        try:
            meta = json.loads(side.read_text())
        except (OSError, ValueError) as err:
            raise UntrustedModelFile(
                f"{p}: no readable sidecar {side.name} ({err}); a synthesizer file is loaded only "
                "with the sidecar Synthesizer.save wrote beside it"
            ) from err
        if not isinstance(meta, dict) or meta.get("format") != MODEL_FORMAT:
            raise UntrustedModelFile(f"{side}: not a {MODEL_FORMAT} sidecar")
        if meta.get("format_version") != FORMAT_VERSION:
            raise UntrustedModelFile(
                f"{side}: format version {meta.get('format_version')!r}; "
                f"this joulepath reads version {FORMAT_VERSION}"
            )
        digest = hashlib.sha256(data).hexdigest()
        if digest != meta.get("sha256"):
            raise UntrustedModelFile(
                f"{p}: SHA-256 {digest[:16]}... does not match {meta.get('sha256', '')[:16]}... recorded in "
                f"{side.name}; the file changed since it was saved. Refusing to unpickle it: refit "
                "the synthesizer (joulepath synth ... --save-model)"
            )
        info = meta["info"]
        saved = info.get("versions", {}).get("sdv")
        installed = _sdv.versions()["sdv"]
        if saved != installed:
            raise InvalidInput(
                f"{p}: saved with sdv {saved}, but sdv {installed} is installed; refit the synthesizer "
                f"or install sdv=={saved}"
            )
        synth = cls(SynthConfig(**meta["config"]))
        synth._model = _sdv.load_model(data)
        rng = np.random.default_rng()
        rng.bit_generator.state = meta["rng_state"]
        synth._rng = rng
        synth._info = info
        return synth


def sidecar_path(path: str | os.PathLike[str]) -> Path:
    """The JSON sidecar of a synthesizer file: ``<path>.json``.

    Examples
    --------
    >>> sidecar_path("tvae.pkl").name
    'tvae.pkl.json'
    """
    p = Path(path)
    return p.with_name(p.name + ".json")


def synthesize(
    table: EnergyTable,
    *,
    n_rows: int,
    config: SynthConfig | None = None,
    repair: Robot | None = None,
    model_path: str | os.PathLike[str] | None = None,
    progress: Callable[[str], None] | None = None,
) -> EnergyTable:
    """Fit a synthesizer on ``table`` and sample ``n_rows`` rows (``joulepath synth``).

    Parameters
    ----------
    table : EnergyTable
        The real table.
    n_rows : int
        Rows to sample.
    config : SynthConfig, optional
    repair : Robot, optional
        Recompute the TCP columns from the joint columns with this robot's
        kinematics (:func:`joulepath.synth.repair_kinematics`).
    model_path : path, optional
        Also save the fitted synthesizer there (and its sidecar ``<path>.json``).
    progress : callable, optional
        Receives short status messages.

    Returns
    -------
    EnergyTable
    """
    if repair is not None:  # refuse a table that cannot be repaired before the (long) fit
        from joulepath.synth._kinematics import _check

        _check(table, repair, where="synthesize")
    synth = Synthesizer(config).fit(table, progress=progress)
    if model_path is not None:
        synth.save(model_path)
        if progress:
            progress(f"saved the synthesizer to {model_path} (+ {sidecar_path(model_path).name})")
    out = synth.sample(n_rows, progress=progress)
    if repair is not None:
        from joulepath.synth._kinematics import repair_kinematics

        out = repair_kinematics(out, repair)
    return out


__all__ = [
    "MIN_ROWS",
    "NotFittedError",
    "SynthConfig",
    "Synthesizer",
    "UntrustedModelFile",
    "finish_frame",
    "model_columns",
    "sidecar_path",
    "synthesize",
]
