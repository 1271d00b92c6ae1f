"""The bundled IRB 2400: published dynamics where the source gives them, and its axis-3 coupling."""

from __future__ import annotations

import numpy as np
import pytest

from joulepath import load_robot
from joulepath.description import (
    axes_to_joints,
    has_axis3_coupling,
    joints_to_axes,
    preset_description,
    preset_path,
    provenance_beside,
)
from joulepath.kinematics import forward_kinematics, link_frames


@pytest.fixture(scope="module")
def robot():
    return load_robot("irb2400")


def test_family_name_is_the_12_1_55_variant(robot):
    assert robot.name == "IRB 2400-12/1.55"
    assert preset_path("irb2400").name == "irb2400-12-1.55.irml"


def test_link_masses_are_the_published_ones_and_sum_to_the_catalogue(robot):
    """Obal & Gierlak 2025: 192, 26.5, 25.7, 29.7, 2.8, 0.8 kg; the base is 380 kg less these."""
    np.testing.assert_allclose(robot.chain.masses, [192.0, 26.5, 25.7, 29.7, 2.8, 0.8])
    desc = robot.description
    assert desc.base.mass == pytest.approx(380.0 - 277.5)


def test_published_centres_of_mass_land_where_the_article_puts_them(robot):
    """At home, link 2's centre is 253.4 mm up the upper arm and 47.7 mm forward of its axis (the
    article's frame 2), link 3's 139.5 mm above and 99.5 mm behind the elbow axis."""
    frames = link_frames(robot.chain, np.zeros(6))
    world = [frames[i, :3, :3] @ robot.chain.coms[i] + frames[i, :3, 3] for i in range(3)]
    np.testing.assert_allclose(world[0], [0.021, 0.022, 0.615 - 0.1885], atol=1e-9)
    np.testing.assert_allclose(world[1], [0.1 + 0.0477, 0.007, 0.615 + 0.2534], atol=1e-9)
    np.testing.assert_allclose(world[2], [0.1 - 0.0995, -0.0097, 1.32 + 0.1395], atol=1e-9)


def test_tool0_at_home_is_where_abb_puts_it(robot):
    """ABB's IRB 2400 at q = 0: flange 100 + 755 + 85 = 940 mm forward, 615 + 705 + 135 = 1455 mm up."""
    pose = forward_kinematics(robot.chain, np.zeros(6))
    np.testing.assert_allclose(pose.position_m, [0.94, 0.0, 1.455], atol=1e-9)


def test_published_friction_is_read_beside_the_description(robot):
    f = robot.friction
    assert f is not None and "friction file" in robot.friction_note
    np.testing.assert_allclose(f.coulomb, [24.2, 31.2, 16.9, 7.9, 13.7, 8.8])
    np.testing.assert_allclose(f.viscous, [11.85, 8.323, 9.3613, 7.1228, 7.2654, 2.323])


def test_axis3_is_q2_plus_q3_and_the_conversion_round_trips(rng):
    desc = preset_description("irb2400")
    assert has_axis3_coupling(desc)
    assert not has_axis3_coupling(preset_description("irb2600"))
    q = rng.uniform(-1, 1, size=(100, 6))
    axes = joints_to_axes(desc, q)
    np.testing.assert_allclose(axes[:, 2], q[:, 1] + q[:, 2])
    np.testing.assert_array_equal(np.delete(axes, 2, axis=1), np.delete(q, 2, axis=1))
    np.testing.assert_allclose(axes_to_joints(desc, axes), q, atol=1e-15)
    other = preset_description("irb2600")
    np.testing.assert_array_equal(joints_to_axes(other, q), q)


def test_the_forearm_keeps_its_angle_when_axis_2_moves_alone(robot):
    """The parallelogram: with axis 3 held, turning axis 2 moves the forearm without turning it."""
    desc = robot.description
    a = np.radians([0.0, -30.0, 20.0, 0.0, 0.0, 0.0])
    b = a.copy()
    b[1] = np.radians(40.0)
    ra = forward_kinematics(robot.chain, axes_to_joints(desc, a)).rotation
    rb = forward_kinematics(robot.chain, axes_to_joints(desc, b)).rotation
    np.testing.assert_allclose(ra, rb, atol=1e-12)


def test_joint3_box_holds_every_pose_the_controller_accepts(robot):
    """Axis 2 -100..110 deg, axis 3 -60..65 deg: serial q3 = axis 3 - axis 2 lies in -170..165 deg."""
    lo, hi = robot.chain.lower, robot.chain.upper
    np.testing.assert_allclose(np.degrees([lo[2], hi[2]]), [-170.0, 165.0], atol=0.01)
    prov = provenance_beside(robot.source)
    names = {p.name: p for p in prov.parameters}
    assert names["axis-3 coupling"].kind == "published" and "BSD" in names["axis-3 coupling"].source
    assert "not enforced" in names["axis ranges"].how
