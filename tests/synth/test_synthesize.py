"""The SDV adapter: config, fit/sample, schema of the output, seeds, save/load and its hash check."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

import joulepath.synth
from joulepath.data import EnergyTable, load_table, save_table, table_columns
from joulepath.errors import InvalidInput, InvalidLog
from joulepath.synth import (
    METHODS,
    NotFittedError,
    SynthConfig,
    Synthesizer,
    UntrustedModelFile,
    kinematic_consistency,
    model_columns,
    sidecar_path,
    synthesize,
)

TINY = {"epochs": 1, "batch_size": 100}


def test_all_is_sorted_and_importable():
    assert joulepath.synth.__all__ == sorted(joulepath.synth.__all__)
    for name in joulepath.synth.__all__:
        assert hasattr(joulepath.synth, name)


def test_import_does_not_load_sdv():
    import subprocess
    import sys

    code = (
        "import sys, joulepath.synth; "
        "print(any(m.split('.')[0] in ('sdv', 'sdmetrics', 'torch', 'sklearn') for m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_model_columns_leave_out_ids_clock_and_total():
    cols = model_columns("full40")
    assert "move_id" not in cols and "t" not in cols and "E" not in cols
    assert set(cols) | {"move_id", "t", "E"} == set(table_columns("full40"))
    assert len(model_columns("joint")) == 18 + 6 + 1


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"method": "gan"}, "unknown method 'gan'; choose one of copula, copulagan, ctgan, tvae"),
        ({"epochs": 0}, "epochs must be a positive integer, got 0"),
        ({"batch_size": 51, "method": "tvae"}, "batch_size must be even"),
        ({"batch_size": 64, "method": "ctgan"}, "multiple of 10 .* got 64; try 60"),
        ({"n_threads": 0}, "n_threads must be a positive integer"),
        ({"rows_per_move": 0}, "rows_per_move must be a positive integer or None"),
        ({"seed": 1.5}, "seed must be an integer or None"),
    ],
)
def test_config_invalid(kwargs, match):
    with pytest.raises(InvalidInput, match=match):
        SynthConfig(**kwargs)


def test_config_is_frozen():
    cfg = SynthConfig()
    with pytest.raises(AttributeError):
        cfg.method = "ctgan"  # type: ignore[misc]


@pytest.mark.parametrize("method", METHODS)
def test_fit_sample_every_method_keeps_the_schema(fitted, energy_table, method):
    synth, out = fitted(method)
    assert synth.is_fitted
    frame = out.frame
    assert list(frame.columns) == list(energy_table.frame.columns)
    assert (frame.dtypes == energy_table.frame.dtypes).all()
    assert len(frame) == 300 and out.feature_set == "full40" and out.robot == energy_table.robot
    assert np.isfinite(frame.to_numpy(dtype=float)).all()
    # derived columns: E is the sum of E1..E6, t the running sum of dt, move_id in blocks
    np.testing.assert_allclose(frame["E"], frame[[f"E{i}" for i in range(1, 7)]].sum(axis=1))
    np.testing.assert_allclose(np.diff(frame["t"]), frame["dt"].to_numpy()[:-1])
    per_move = synth.info["rows_per_move"]
    assert per_move == round(len(energy_table.frame) / energy_table.n_moves)
    assert (frame["move_id"].to_numpy() == np.arange(300) // per_move).all()
    # samples stay within the real ranges (SDV's enforce_min_max_values)
    cols = list(model_columns("full40"))
    real = energy_table.frame[cols]
    assert (frame[cols].min() >= real.min() - 1e-9).all() and (frame[cols].max() <= real.max() + 1e-9).all()
    source = out.sources[0]
    assert source["synthetic"] == method and source["real_fingerprint"] == energy_table.fingerprint()


def test_sample_twice_gives_new_rows(fitted):
    synth, first = fitted("copula")
    again = synth.sample(300)
    assert not again.frame.equals(first.frame)


@pytest.mark.parametrize("method", METHODS)
def test_seed_reproduces_a_run_and_another_seed_differs(joint_table, method):
    def run(seed):
        config = SynthConfig(method=method, seed=seed, **TINY)
        return Synthesizer(config).fit(joint_table).sample(120).frame

    first = run(11)
    pd.testing.assert_frame_equal(first, run(11), check_exact=True)
    assert not first.equals(run(12))
    assert list(first.columns) == list(table_columns("joint"))


def test_fit_leaves_global_random_state_alone(joint_table):
    import torch

    before_np = np.random.get_state()[1].copy()  # noqa: NPY002
    before_torch = torch.get_rng_state().clone()
    threads = torch.get_num_threads()
    Synthesizer(SynthConfig(method="tvae", seed=3, **TINY)).fit(joint_table).sample(10)
    assert (np.random.get_state()[1] == before_np).all()  # noqa: NPY002
    assert torch.equal(torch.get_rng_state(), before_torch)
    assert torch.get_num_threads() == threads


def test_sample_before_fit_refused():
    with pytest.raises(NotFittedError, match=r"not fitted yet; call fit\(table\)"):
        Synthesizer(SynthConfig(method="copula")).sample(10)
    with pytest.raises(NotFittedError, match="before save"):
        Synthesizer().save("nowhere.pkl")


@pytest.mark.parametrize("n_rows", [0, -3, 2.5, True])
def test_sample_invalid_n_rows(fitted, n_rows):
    synth, _ = fitted("copula")
    with pytest.raises(InvalidInput, match="n_rows must be a positive integer"):
        synth.sample(n_rows)


def test_fit_refuses_bad_tables(energy_table):
    synth = Synthesizer(SynthConfig(method="copula"))
    with pytest.raises(InvalidInput, match="expects an EnergyTable"):
        synth.fit(energy_table.frame)  # type: ignore[arg-type]
    few = EnergyTable(frame=energy_table.frame.iloc[:5], feature_set="full40")
    with pytest.raises(InvalidLog, match="has 5 rows; at least 10"):
        synth.fit(few)
    nan = energy_table.frame.copy()
    nan.loc[3, "dq2"] = np.nan
    nan.loc[4, "E5"] = np.inf
    with pytest.raises(InvalidLog, match="column\\(s\\) dq2, E5 hold NaN or infinite"):
        synth.fit(EnergyTable(frame=nan, feature_set="full40"))
    missing = energy_table.frame.drop(columns=["ddz"])
    with pytest.raises(InvalidLog, match="missing column\\(s\\) ddz"):
        synth.fit(EnergyTable(frame=missing, feature_set="full40"))


def test_save_load_round_trip_gives_the_same_samples(fitted, tmp_path):
    synth, _ = fitted("tvae")
    path = synth.save(tmp_path / "tvae.pkl")
    side = json.loads(sidecar_path(path).read_text())
    assert side["format"] == "joulepath-synthesizer" and len(side["sha256"]) == 64
    loaded = Synthesizer.load(path)
    assert loaded.config == synth.config and loaded.info == synth.info
    pd.testing.assert_frame_equal(loaded.sample(50).frame, synth.sample(50).frame, check_exact=True)


def test_load_refuses_a_tampered_file(fitted, tmp_path):
    synth, _ = fitted("copula")
    path = synth.save(tmp_path / "copula.pkl")
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(UntrustedModelFile, match="does not match .* Refusing to unpickle"):
        Synthesizer.load(path)


def test_load_refuses_a_file_without_sidecar(tmp_path):
    import pickle

    path = tmp_path / "other.pkl"
    path.write_bytes(pickle.dumps({"not": "a synthesizer"}))
    with pytest.raises(UntrustedModelFile, match="no readable sidecar other.pkl.json"):
        Synthesizer.load(path)
    sidecar_path(path).write_text(json.dumps({"format": "something-else"}))
    with pytest.raises(UntrustedModelFile, match="not a joulepath-synthesizer sidecar"):
        Synthesizer.load(path)


def test_load_refuses_another_sdv_version(fitted, tmp_path):
    synth, _ = fitted("copula")
    path = synth.save(tmp_path / "copula.pkl")
    side = json.loads(sidecar_path(path).read_text())
    side["info"]["versions"]["sdv"] = "0.0.1"
    sidecar_path(path).write_text(json.dumps(side))
    with pytest.raises(InvalidInput, match="saved with sdv 0.0.1, but sdv .* is installed"):
        Synthesizer.load(path)


def test_synthesize_with_repair_and_saved_model(joint_table, energy_table, tmp_path, irb120):
    messages = []
    config = SynthConfig(method="copula", seed=5, rows_per_move=25)
    small = EnergyTable(frame=energy_table.frame.iloc[:200], feature_set="full40", robot=energy_table.robot)
    out = synthesize(
        small,
        n_rows=100,
        config=config,
        repair=irb120,
        model_path=tmp_path / "m.pkl",
        progress=messages.append,
    )
    assert kinematic_consistency(out, irb120) == 1.0
    assert out.frame["move_id"].max() == 3
    assert (tmp_path / "m.pkl").exists() and (tmp_path / "m.pkl.json").exists()
    assert any(m.startswith("fitting copula on 200 rows") for m in messages)
    saved = load_table(save_table(out, tmp_path / "s.parquet"))
    pd.testing.assert_frame_equal(saved.frame, out.frame)
