"""Plausible models within a model's stated uncertainty (for a Monte Carlo statement of a result)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from joulepath.description._model import Chain
from joulepath.description._provenance import Uncertainty


def sample_chains(
    chain: Chain, uncertainty: Uncertainty, n_samples: int, *, rng: np.random.Generator
) -> list[Chain]:
    """``n_samples`` chains whose link dynamics are drawn uniformly within ``uncertainty``.

    Per moving link, independently: the mass times a factor in ``1 ± link_mass_rel``, the
    inertia about the centre of mass times a factor in ``1 ± link_inertia_rel`` (a positive
    factor keeps it positive definite and within the triangle inequality), the centre of mass
    moved by up to ``± link_com_m`` along each axis of the joint frame. Kinematics and limits
    are the nominal ones. With a zero-width uncertainty every sample is the nominal chain.

    Parameters
    ----------
    chain : Chain
    uncertainty : Uncertainty
    n_samples : int
        At least 1.
    rng : numpy.random.Generator

    Returns
    -------
    list of Chain, length n_samples
    """
    n = chain.n_joints
    masses = np.asarray(chain.masses, dtype=float)
    coms = np.asarray(chain.coms, dtype=float)
    inertias = np.asarray(chain.inertias, dtype=float)
    f_mass = rng.uniform(
        1.0 - uncertainty.link_mass_rel, 1.0 + uncertainty.link_mass_rel, size=(n_samples, n)
    )
    f_inertia = rng.uniform(
        1.0 - uncertainty.link_inertia_rel, 1.0 + uncertainty.link_inertia_rel, size=(n_samples, n)
    )
    shift = rng.uniform(-uncertainty.link_com_m, uncertainty.link_com_m, size=(n_samples, n, 3))
    return [
        replace(
            chain,
            masses=masses * f_mass[k],
            coms=coms + shift[k],
            inertias=inertias * f_inertia[k][:, None, None],
        )
        for k in range(n_samples)
    ]
