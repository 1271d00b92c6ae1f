"""Hypothesis settings for property tests (skipped when hypothesis is missing)."""

import pytest

hypothesis = pytest.importorskip("hypothesis")
hypothesis.settings.register_profile("ci", deadline=None, print_blob=True, max_examples=40)
hypothesis.settings.load_profile("ci")
