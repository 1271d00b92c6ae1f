"""A small simulated lab dataset shared by the learn tests."""

import pytest

import joulepath
from joulepath.data import ingest
from joulepath.sim import simulate


@pytest.fixture(scope="session")
def lab_tables(tmp_path_factory):
    d = tmp_path_factory.mktemp("lab")
    robot = joulepath.load_robot("irb120")
    train = ingest([simulate(d / "train.csv", plant="lab", n_moves=25, seed=1).log], robot=robot)
    test = ingest([simulate(d / "test.csv", plant="lab", n_moves=12, seed=2).log], robot=robot)
    return train, test


@pytest.fixture(scope="session")
def trained(lab_tables, tmp_path_factory):
    from joulepath.learn import TrainConfig, train

    out = tmp_path_factory.mktemp("models")
    report = train(*lab_tables, TrainConfig(targets=("E",), cv=3, seed=0), out)
    return report
