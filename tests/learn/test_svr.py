"""ScalableSVR: liblinear for the linear kernel, a stated row sample for the other kernels."""

import warnings

import numpy as np
import pytest
from sklearn.svm import SVR, LinearSVR
from sklearn.utils.estimator_checks import parametrize_with_checks

from joulepath.learn import KERNEL_SVR_MAX_ROWS, ScalableSVR, SubsampleWarning


def _expected_failures(estimator):
    if estimator.kernel == "linear":
        return {}
    return {  # as for sklearn's own SVR
        "check_sample_weight_equivalence_on_dense_data": "libsvm's sample weights rescale C per row"
    }


@parametrize_with_checks(
    [ScalableSVR(), ScalableSVR(kernel="linear")], expected_failed_checks=_expected_failures
)
def test_sklearn_compatible(estimator, check):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SubsampleWarning)
        check(estimator)


def _data(n, seed=0):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(n, 4))
    return X, X @ np.array([1.0, -2.0, 0.5, 0.0]) + 0.01 * rng.normal(size=n)


def test_linear_kernel_uses_liblinear_on_every_row():
    X, y = _data(3000)
    model = ScalableSVR(kernel="linear", C=1.0, epsilon=0.001, max_rows=100, random_state=0).fit(X, y)
    assert isinstance(model.estimator_, LinearSVR) and model.n_fit_rows_ == 3000
    np.testing.assert_allclose(model.estimator_.coef_, [1.0, -2.0, 0.5, 0.0], atol=0.01)
    assert model.predict(X[:1]).shape == (1,) and model.predict(X).shape == (3000,)


def test_kernel_svr_subsamples_above_max_rows_and_says_so():
    X, y = _data(600)
    with pytest.warns(SubsampleWarning, match=r"kernel SVR \(rbf\) fitted on a random 200 of 600 rows"):
        model = ScalableSVR(kernel="rbf", max_rows=200, random_state=0).fit(X, y)
    assert isinstance(model.estimator_, SVR) and model.n_fit_rows_ == 200
    assert model.estimator_.support_vectors_.shape[0] <= 200
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # at or below max_rows: all rows, no warning
        assert ScalableSVR(kernel="poly", degree=2, max_rows=600).fit(X, y).n_fit_rows_ == 600
    assert KERNEL_SVR_MAX_ROWS == ScalableSVR().max_rows == 5000


def test_subsample_is_seeded():
    X, y = _data(600)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SubsampleWarning)
        a = ScalableSVR(max_rows=100, random_state=1).fit(X, y).predict(X)
        b = ScalableSVR(max_rows=100, random_state=1).fit(X, y).predict(X)
        c = ScalableSVR(max_rows=100, random_state=2).fit(X, y).predict(X)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


def test_invalid_parameters_are_refused_at_fit():
    X, y = _data(50)
    with pytest.raises(ValueError, match="kernel"):
        ScalableSVR(kernel="precomputed").fit(X, y)
    with pytest.raises(ValueError, match="max_rows"):
        ScalableSVR(max_rows=0).fit(X, y)
