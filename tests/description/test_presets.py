"""The bundled IRB 120: IRML (DH frames) against the ROS-Industrial URDF it was converted from."""

import json
from pathlib import Path

import numpy as np
import pytest

from joulepath.description import (
    PRESETS,
    chain_from_description,
    chain_from_urdf,
    dh_transform,
    preset_description,
    preset_path,
)
from joulepath.errors import InvalidRobotDescription
from joulepath.kinematics import link_frames

REFERENCE = Path(__file__).parents[3] / "shared" / "reference" / "irb120_public_data.json"


@pytest.fixture(scope="module")
def chains():
    return chain_from_description(preset_description("irb120")), chain_from_urdf(
        preset_path("irb120", fmt="urdf")
    )


def _world_mass_properties(chain, q):
    frames = link_frames(chain, q)
    rot, origin = frames[..., :3, :3], frames[..., :3, 3]
    coms = origin + np.einsum("...iab,ib->...ia", rot, chain.coms)
    inertias = rot @ chain.inertias @ np.swapaxes(rot, -1, -2)
    return coms, inertias


def test_irml_and_urdf_give_same_world_mass_properties(chains, rng):
    """The conversion URDF link frame -> DH frame keeps every body where it was."""
    irml, urdf = chains
    q = rng.uniform(-3, 3, size=(50, 6))
    c1, i1 = _world_mass_properties(irml, q)
    c2, i2 = _world_mass_properties(urdf, q)
    np.testing.assert_allclose(c1, c2, atol=1e-12)
    np.testing.assert_allclose(i1, i2, atol=1e-12)
    np.testing.assert_array_equal(irml.masses, urdf.masses)


def test_recorded_conversion_transforms(rng):
    """URDF link i -> DH frame i is constant over q (recorded here as in the reference JSON)."""
    desc = preset_description("irb120")
    urdf = chain_from_urdf(preset_path("irb120", fmt="urdf"))
    expected = None
    if REFERENCE.exists():
        expected = json.loads(REFERENCE.read_text())["derived_by_helper"]["dh_vs_urdf_check"][
            "T_urdf_link_i_to_dh_frame_i"
        ]
    for q in rng.uniform(-2, 2, size=(5, 6)):
        f_urdf = link_frames(urdf, q)
        f_dh = np.eye(4)
        for i, j in enumerate(desc.joints):
            f_dh = f_dh @ dh_transform(j.sign * q[i] + j.offset, j.d, j.r, j.alpha)
            rel = np.linalg.inv(f_urdf[i]) @ f_dh
            if expected is not None:
                np.testing.assert_allclose(rel, expected[f"link_{i + 1}"], atol=1e-12)
            assert np.allclose(rel[:3, :3] @ rel[:3, :3].T, np.eye(3))


def test_irb120_inertias_are_the_published_ones_rotated():
    desc = preset_description("irb120")
    link3 = desc.joints[2].inertial.inertia_array
    # URDF link_3: ixx 0.00835606, iyy 0.016713, izz 0.0126984; DH frame 3 permutes the axes
    assert sorted(np.diag(link3)) == pytest.approx(sorted([0.00835606, 0.016713, 0.0126984]))
    assert np.trace(link3) == pytest.approx(0.00835606 + 0.016713 + 0.0126984)


def test_preset_path_unknown_name():
    assert PRESETS[0] == "irb120"
    with pytest.raises(InvalidRobotDescription, match="unknown robot 'irb999'; bundled robots: irb120, irb1"):
        preset_path("irb999")
