"""Regenerate the bundled IRB 120 preset (irb120.urdf and irb120.irml) from ../shared/reference.

Provenance of every number:

* ``irb120.urdf``: ROS-Industrial abb_experimental, abb_irb120_support/urdf/
  irb120_3_58_macro.xacro (Apache-2.0), macro expanded with an empty prefix; visual
  and collision meshes and xacro materials removed; nothing else changed.
* ``irb120.irml``: DH of thesis Table 2.1 with ABB's joint zero (theta offsets 0,
  -90, 0, 0, 0, 180 deg); masses, centres of mass and inertias of the URDF above,
  re-expressed in the DH link frames (p_dh = R^T (p_link - t), I_dh = R^T I R with
  (R, t) the constant transform from URDF link frame i to DH frame i, computed here
  at q = 0 and checked at random q by tests/description/test_presets.py); ranges and
  max speeds of the ABB data sheet ROB0149EN_D; range sets "lab" (thesis Table 3.1)
  and "collection" (thesis Appendix D.1). No <effort> (torque) limits: no public source
  gives them for the IRB 120 (the ROS-I URDF has effort="0", i.e. unspecified; ABB's
  product specification gives wrist inertia limits only); see presets/NOTICE.txt.

Run from the repository root:  python scripts/make_irb120_preset.py
"""

from __future__ import annotations

import json
import math
import re
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "reference"
PRESETS = ROOT / "src" / "joulepath" / "description" / "presets"
sys.path.insert(0, str(ROOT / "src"))

from joulepath.description import (  # noqa: E402
    Inertial,
    JointDescription,
    RangeSet,
    RobotDescription,
    chain_from_urdf,
    irml_string,
)
from joulepath.description._chain import dh_transform  # noqa: E402

DEG = math.pi / 180


def expand_xacro() -> str:
    raw = next(SHARED.glob("raw/ros-industrial_abb_experimental@*"))
    text = (raw / "abb_irb120_support/urdf/irb120_3_58_macro.xacro").read_text()
    text = text.replace("${prefix}", "").replace("${radians(90)}", repr(math.pi / 2))
    text = re.sub(r"<visual>.*?</visual>", "", text, flags=re.S)
    text = re.sub(r"<collision>.*?</collision>", "", text, flags=re.S)
    text = re.sub(r"<xacro:include[^>]*/>", "", text)
    text = re.sub(r"<xacro:macro[^>]*>", "", text)
    text = text.replace("</xacro:macro>", "")
    text = re.sub(r'<robot xmlns:xacro="[^"]*">', '<robot name="abb_irb120_3_58">', text)
    text = re.sub(r"<\?xml[^>]*\?>", "", text)
    text = re.sub(r"\n\s*\n+", "\n", text)
    header = (
        '<?xml version="1.0"?>\n'
        "<!-- ABB IRB 120-3/0.6 from ROS-Industrial abb_experimental (Apache-2.0), commit\n"
        "     20b9cf86ad274e4f98540b9c9efe59f94245d2d1, abb_irb120_support/urdf/"
        "irb120_3_58_macro.xacro,\n"
        '     expanded with prefix="" and meshes removed by scripts/make_irb120_preset.py.'
        " -->\n"
    )
    return header + text.strip() + "\n"


def main() -> None:
    data = json.loads((SHARED / "irb120_public_data.json").read_text())
    urdf_path = PRESETS / "irb120.urdf"
    urdf_path.write_text(expand_xacro())
    urdf_chain = chain_from_urdf(urdf_path)
    dh = data["dh_standard"]
    links = data["urdf_ros_industrial"]["links"]
    sheet = data["abb_spec_sheet"]
    # world frames at q = 0: URDF link frames and DH frames
    urdf_frame = np.eye(4)
    dh_frame = np.eye(4)
    joints = []
    for i in range(6):
        urdf_frame = urdf_frame @ urdf_chain.placements[i]
        dh_frame = dh_frame @ dh_transform(
            dh["theta_offset_rad"][i], dh["d_m"][i], dh["a_m"][i], dh["alpha_rad"][i]
        )
        rel = np.linalg.inv(urdf_frame) @ dh_frame  # URDF link i frame -> DH frame i
        rot, t = rel[:3, :3], rel[:3, 3]
        link = links[f"link_{i + 1}"]
        inertia_urdf = link["inertia_kgm2_about_com"]
        ii = np.array(
            [
                [inertia_urdf["ixx"], inertia_urdf["ixy"], inertia_urdf["ixz"]],
                [inertia_urdf["ixy"], inertia_urdf["iyy"], inertia_urdf["iyz"]],
                [inertia_urdf["ixz"], inertia_urdf["iyz"], inertia_urdf["izz"]],
            ]
        )
        com = rot.T @ (np.array(link["com_xyz_m"]) - t)
        inertia = rot.T @ ii @ rot
        lo, hi = sheet["axis_working_range_deg"][f"axis_{i + 1}"]
        joints.append(
            JointDescription(
                id=i + 1,
                type="T" if i in (0, 3, 5) else "R",
                xi=1,
                variable=f"q{i + 1}",
                offset=dh["theta_offset_rad"][i],
                d=dh["d_m"][i],
                r=dh["a_m"][i],
                alpha=dh["alpha_rad"][i],
                inertial=Inertial.from_arrays(link["mass_kg"], np.round(com, 12), np.round(inertia, 15)),
                lower=lo * DEG,
                upper=hi * DEG,
                velocity=sheet["axis_max_speed_deg_s"][f"axis_{i + 1}"] * DEG,
            )
        )
    base = links["base_link"]
    bi = base["inertia_kgm2_about_com"]
    lab = [(-90, 90), (-10, 45), (-100, 40), (-160, 160), (-120, 120), (-400, 400)]
    collection = [(-120, 120), (-55, 70), (-100, 40), (-160, 160), (-120, 120), (-400, 400)]
    desc = RobotDescription(
        name="IRB 120",
        manufacturer="ABB",
        info=(
            ("variant", sheet["variant"]),
            ("carrying-capacity", "3.0"),
            ("reach", "0.58"),
            ("configuration", "Articulated"),
            ("ir-type", "Serial"),
            ("manipulator-mass", "25"),
            ("joint-zero", "ABB: q = 0 is the home pose, tool0 at (374, 0, 630) mm"),
            ("frames", "center and inertia in the link's DH frame; inertia about the COM"),
            ("source/dynamics", "ROS-Industrial abb_experimental irb120_3_58 (Apache-2.0), CAD"),
            ("source/limits", "ABB data sheet ROB0149EN_D (May 2012)"),
            ("source/kinematics", "thesis Table 2.1 with ABB offsets"),
        ),
        joints=tuple(joints),
        base=Inertial.from_arrays(
            base["mass_kg"],
            base["com_xyz_m"],
            [
                [bi["ixx"], bi["ixy"], bi["ixz"]],
                [bi["ixy"], bi["iyy"], bi["iyz"]],
                [bi["ixz"], bi["iyz"], bi["izz"]],
            ],
        ),
        range_sets=(
            RangeSet(
                name="lab",
                lower=tuple(a * DEG for a, _ in lab),
                upper=tuple(b * DEG for _, b in lab),
            ),
            RangeSet(
                name="collection",
                lower=tuple(a * DEG for a, _ in collection),
                upper=tuple(b * DEG for _, b in collection),
            ),
        ),
    )
    (PRESETS / "irb120.irml").write_text(irml_string(desc))
    print(f"wrote {urdf_path} and {PRESETS / 'irb120.irml'}")


if __name__ == "__main__":
    main()
