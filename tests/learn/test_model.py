"""Saved models: identical predictions after a round trip, fast rows, refusals."""

import json
import shutil

import numpy as np
import pytest

from joulepath.errors import InvalidModel
from joulepath.learn import EnergyModel


@pytest.mark.parametrize("family", ["mlp", "svr", "par", "xgb", "bases"])
def test_round_trip_gives_identical_predictions(trained, lab_tables, family, tmp_path):
    _, test = lab_tables
    folder = trained.models[f"{family}-E"]
    model = EnergyModel.load(folder)
    copy = EnergyModel.load(model.save(tmp_path / "copy"))
    np.testing.assert_array_equal(model.predict(test.frame), copy.predict(test.frame))
    X = test.frame[list(model.input_columns)].to_numpy()
    np.testing.assert_allclose(model.predict_rows(X), model.pipeline.predict(X), rtol=0, atol=1e-10)


def test_mlp_numpy_forward_pass_equals_sklearn(trained, lab_tables):
    _, test = lab_tables
    model = EnergyModel.load(trained.models["mlp-E"])
    assert model._forward is not None
    X = test.frame[list(model.input_columns)].to_numpy()
    np.testing.assert_allclose(model.predict_rows(X), model.pipeline.predict(X), rtol=0, atol=1e-10)


def test_predict_refuses_missing_columns(trained, lab_tables):
    _, test = lab_tables
    model = EnergyModel.load(trained.models["par-E"])
    with pytest.raises(InvalidModel, match=r"lacks column\(s\) ddq2, dt that the par model for E"):
        model.predict(test.frame.drop(columns=["ddq2", "dt"]))
    with pytest.raises(InvalidModel, match=r"X has shape \(3, 5\), but the model expects \(n_rows, 41\)"):
        model.predict_rows(np.zeros((3, 5)))


def test_load_refuses_unknown_types(trained, tmp_path):
    """A skops file holding a type outside the allowlist is refused before anything is built."""
    import skops.io as sio
    from sklearn.pipeline import Pipeline

    folder = tmp_path / "evil"
    shutil.copytree(trained.models["par-E"], folder)
    sio.dump(Pipeline([("model", _Unknown())]), folder / "model.skops")
    with pytest.raises(InvalidModel, match=r"refused, it contains types outside the allowlist: .*_Unknown"):
        EnergyModel.load(folder)


class _Unknown:
    def fit(self, X, y=None):
        return self

    def predict(self, X):
        return np.zeros(len(X))


def test_load_refuses_bad_folders(trained, tmp_path):
    with pytest.raises(InvalidModel, match="no card.json"):
        EnergyModel.load(tmp_path)
    folder = tmp_path / "xgb"
    shutil.copytree(trained.models["xgb-E"], folder)
    card = json.loads((folder / "card.json").read_text())
    card["file"] = "model.pkl"
    (folder / "card.json").write_text(json.dumps(card))
    with pytest.raises(InvalidModel, match="must be a .json booster"):
        EnergyModel.load(folder)
    del card["target"]
    (folder / "card.json").write_text(json.dumps(card))
    with pytest.raises(InvalidModel, match="the card lacks 'target'"):
        EnergyModel.load(folder)
