import numpy as np
import pytest

from joulepath._rng import check_rng, integer_seed


def test_check_rng_seed_reproduces_and_differs():
    assert check_rng(1).random() == check_rng(1).random()
    assert check_rng(1).random() != check_rng(2).random()
    gen = np.random.default_rng(0)
    assert check_rng(gen) is gen
    assert isinstance(check_rng(None), np.random.Generator)


@pytest.mark.parametrize("bad", [1.5, "3", True, np.random.RandomState(0)])
def test_check_rng_rejects_other_types(bad):
    with pytest.raises(TypeError, match="seed must be an int"):
        check_rng(bad)


def test_integer_seed_is_plain_int():
    seed = integer_seed(np.random.default_rng(0))
    assert type(seed) is int and 0 <= seed < 2**31 - 1
