# ruff: noqa: E501  (provenance and citation strings, kept whole so they read as one line each)
"""Regenerate the bundled ABB range (``presets/irbNNNN-*.irml``, ``.urdf``, ``.provenance.toml``).

Where every number comes from (also written into each model's provenance file):

* Kinematics (joint origins, hence the DH lengths d1, a1, a2, a3, d4, d6), axis ranges and
  axis speeds: the ROS-Industrial URDF/xacro of the variant (``ros-industrial/abb_experimental``
  or ``ros-industrial/abb``, Apache-2.0; the commit is recorded). ROS-Industrial's authors took
  them from ABB's product specifications; they are used here as the URDF gives them. The IRB 140
  has no licensed public URDF: its kinematics, ranges and speeds are ABB's data-sheet values,
  written here by hand (see ``IRB140``) and stated as such.
* Manipulator mass, rated payload, reach: ABB's data sheet of the variant (the table below),
  stated as published with a ±5 % bound (they were not re-read from ABB's document when this
  script was written).
* Link masses, centres of mass and inertias: ESTIMATED. ABB publishes none. For arms with
  licensed collision meshes: the meshes' volume properties (signed tetrahedra, exact for a closed
  mesh) at one uniform density, that density chosen so that base plus links weigh the catalogue
  mass. For the IRB 140: the IRB 120's CAD inertials (ROS-I, Apache-2.0) scaled (masses to the
  catalogue mass, lengths by the reach ratio). The bound on each comes from applying the mesh
  method to the IRB 120, whose CAD inertials are known (``validate_on_irb120``).

Nothing of the meshes is copied: only the numbers computed from them are written.

Run from the repository root, with local clones (bare or not) of the two ROS-I repositories::

    python scripts/make_abb_presets.py --abb-experimental PATH --abb PATH
"""

from __future__ import annotations

import argparse
import math
import re
import struct
import subprocess
import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
PRESETS = ROOT / "src" / "joulepath" / "description" / "presets"
sys.path.insert(0, str(ROOT / "src"))

from joulepath.description import (  # noqa: E402
    Inertial,
    JointDescription,
    RangeSet,
    RobotDescription,
    chain_from_urdf,
    irml_string,
    preset_description,
)
from joulepath.description._chain import dh_transform, dynamics_fingerprint  # noqa: E402

DEG = math.pi / 180
CATALOGUE_BOUND = 0.05
"""Relative bound on the catalogue's manipulator mass, payload and reach as written here."""


@dataclass(frozen=True)
class Variant:
    id: str
    family: str
    abb_name: str
    payload_kg: float
    reach_m: float
    mass_kg: float
    repo: str  # "abb_experimental", "abb" or "" (hand-written kinematics)
    xacro: str
    default: bool = False


VARIANTS = (
    Variant("irb140-6-0.8", "irb140", "IRB 140-6/0.8", 6.0, 0.81, 98.0, "", "", True),
    Variant(
        "irb1200-7-0.7", "irb1200", "IRB 1200-7/0.7", 7.0, 0.703, 52.0, "abb_experimental",
        "abb_irb1200_support/urdf/irb1200_7_70_macro.xacro", True,
    ),
    Variant(
        "irb1200-5-0.9", "irb1200", "IRB 1200-5/0.9", 5.0, 0.901, 54.0, "abb_experimental",
        "abb_irb1200_support/urdf/irb1200_5_90_macro.xacro",
    ),
    Variant(
        "irb1600-6-1.2", "irb1600", "IRB 1600-6/1.2", 6.0, 1.2, 250.0, "abb_experimental",
        "abb_irb1600_support/urdf/irb1600_6_12_macro.xacro",
    ),
    Variant(
        "irb1600-8-1.45", "irb1600", "IRB 1600-8/1.45", 8.0, 1.45, 250.0, "abb_experimental",
        "abb_irb1600_support/urdf/irb1600_8_145_macro.xacro", True,
    ),
    Variant(
        "irb2600-12-1.65", "irb2600", "IRB 2600-12/1.65", 12.0, 1.65, 272.0, "abb_experimental",
        "abb_irb2600_support/urdf/irb2600_12_165_macro.xacro", True,
    ),
    Variant(
        "irb4600-20-2.50", "irb4600", "IRB 4600-20/2.50", 20.0, 2.51, 412.0, "abb_experimental",
        "abb_irb4600_support/urdf/irb4600_20_250_macro.xacro",
    ),
    Variant(
        "irb4600-40-2.55", "irb4600", "IRB 4600-40/2.55", 40.0, 2.55, 435.0, "abb_experimental",
        "abb_irb4600_support/urdf/irb4600_40_255_macro.xacro", True,
    ),
    Variant(
        "irb4600-60-2.05", "irb4600", "IRB 4600-60/2.05", 60.0, 2.05, 425.0, "abb_experimental",
        "abb_irb4600_support/urdf/irb4600_60_205_macro.xacro",
    ),
    Variant(
        "irb6700-200-2.60", "irb6700", "IRB 6700-200/2.60", 200.0, 2.60, 1170.0, "abb_experimental",
        "abb_irb6700_support/urdf/irb6700_200_260_macro.xacro", True,
    ),
    Variant(
        "irb6700-235-2.65", "irb6700", "IRB 6700-235/2.65", 235.0, 2.65, 1170.0, "abb_experimental",
        "abb_irb6700_support/urdf/irb6700_235_265_macro.xacro",
    ),
)  # fmt: skip

IRB140 = {
    # ABB data sheet IRB 140 (axis working range and axis max speed of the standard arm), and the
    # arm's dimension drawing (d1 352, a1 70, a2 360, d4 380, d6 65 mm).
    "origins": [(0, 0, 0), (0.070, 0, 0.352), (0, 0, 0.360), (0, 0, 0), (0.380, 0, 0), (0.065, 0, 0)],
    "ranges_deg": [(-180, 180), (-90, 110), (-230, 50), (-200, 200), (-115, 115), (-400, 400)],
    "speeds_deg_s": [200, 200, 260, 360, 360, 450],
}
AXES = ("0 0 1", "0 1 0", "0 1 0", "1 0 0", "0 1 0", "1 0 0")
LINKS = ("base_link", "link_1", "link_2", "link_3", "link_4", "link_5", "link_6")

# ---------------------------------------------------------------------------- sources


def git_show(repo: Path, path: str) -> bytes:
    return subprocess.run(
        ["git", "--git-dir", str(repo), "show", f"HEAD:{path}"], capture_output=True, check=True
    ).stdout


def git_head(repo: Path) -> str:
    out = subprocess.run(
        ["git", "--git-dir", str(repo), "rev-parse", "HEAD"], capture_output=True, check=True
    )
    return out.stdout.decode().strip()


def _num(text: str) -> float:
    """A xacro number: ``0.495``, ``${radians(-180)}``, ``-${pi}``, ``-${radians(65)}``."""
    t = text.strip()
    sign = 1.0
    if t.startswith("-$"):
        sign, t = -1.0, t[1:]
    m = re.fullmatch(r"\$\{(.*)\}", t)
    if m is None:
        return sign * float(t)
    inner = m.group(1).strip()
    r = re.fullmatch(r"radians\((.*)\)", inner)
    if r:
        return sign * float(eval(r.group(1), {"__builtins__": {}})) * DEG  # noqa: S307 - our own script
    return sign * float(eval(inner, {"__builtins__": {}, "pi": math.pi}))  # noqa: S307


def read_xacro(
    text: str,
) -> tuple[list[tuple[float, float, float]], list[tuple[float, float, float]], dict[str, str]]:
    """Joint origins, (lower, upper, velocity) of joint_1..6 and each link's collision mesh."""
    origins, limits = [], []
    for i in range(1, 7):
        m = re.search(rf'<joint[^>]*name="\$\{{prefix\}}joint_{i}"[^>]*>(.*?)</joint>', text, re.S)
        assert m, f"joint_{i}"
        body = m.group(1)
        o = re.search(r'<origin[^>]*xyz="([^"]+)"[^>]*rpy="([^"]+)"', body) or re.search(
            r'<origin[^>]*rpy="([^"]+)"[^>]*xyz="([^"]+)"', body
        )
        assert o
        xyz, rpy = (
            (o.group(1), o.group(2)) if "xyz" in o.group(0).split("rpy")[0] else (o.group(2), o.group(1))
        )
        assert all(float(v) == 0.0 for v in rpy.split()), rpy
        origins.append(tuple(float(v) for v in xyz.split()))
        axis = re.search(r'<axis xyz="([^"]+)"', body)
        assert axis and axis.group(1).split() == AXES[i - 1].split(), (i, axis)
        lim = re.search(r"<limit([^>]*)/>", body)
        assert lim
        attrs = dict(re.findall(r'(\w+)="([^"]*)"', lim.group(1)))
        limits.append((_num(attrs["lower"]), _num(attrs["upper"]), _num(attrs["velocity"])))
    meshes = {}
    for link in LINKS:
        m = re.search(
            rf'<link name="\$\{{prefix\}}{link}">.*?<collision.*?<mesh filename="package://([^"]+)"',
            text,
            re.S,
        )
        assert m, link
        pkg, _, rest = m.group(1).partition("/")
        meshes[link] = f"{pkg}/{rest}"
    return origins, limits, meshes  # type: ignore[return-value]


# ---------------------------------------------------------------------------- meshes


def read_stl(data: bytes) -> np.ndarray:
    if data[:5] == b"solid" and b"facet" in data[:400]:
        v = [
            [float(x) for x in line.split()[1:4]]
            for line in data.decode().splitlines()
            if line.strip().startswith("vertex")
        ]
        return np.array(v).reshape(-1, 3, 3)
    n = struct.unpack("<I", data[80:84])[0]
    rec = np.frombuffer(
        data[84 : 84 + 50 * n], dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    )
    return rec["v"].astype(float)


def volume_properties(tri: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume (m³), centroid (m) and inertia about the centroid per unit density (m⁵) of a closed
    mesh: signed tetrahedra from the origin."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    v = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    vol = float(v.sum())
    s = a + b + c
    com = (v[:, None] * s).sum(0) / 4.0 / vol
    outer = lambda x: np.einsum("ni,nj->nij", x, x)  # noqa: E731
    second = (v[:, None, None] / 20.0 * (outer(a) + outer(b) + outer(c) + outer(s))).sum(0)
    about_com = second - vol * np.outer(com, com)
    inertia = np.trace(about_com) * np.eye(3) - about_com
    return vol, com, inertia


# ---------------------------------------------------------------------------- model


def dh_params(origins: list[tuple[float, float, float]]) -> dict[str, float]:
    """DH lengths of the ABB layout from the URDF joint origins (all rpy zero, axes z y y x y x)."""
    o = np.array(origins)
    assert abs(o[:, 1].sum()) < 1e-12 and abs(o[3, 1]) + abs(o[4, 1]) + abs(o[5, 1]) < 1e-12, o
    assert o[2, 0] == 0 and o[4, 2] == 0 and o[5, 2] == 0 and o[2, 2] > 0, o
    return {
        "d1": o[0, 2] + o[1, 2],
        "a1": o[0, 0] + o[1, 0],
        "a2": o[2, 2],
        "a3": o[3, 2],
        "d4": o[3, 0] + o[4, 0],
        "d6": o[5, 0],
    }


def dh_rows(k: dict[str, float]) -> list[tuple[float, float, float, float]]:
    """(theta offset, d, r, alpha) per joint: the IRB 120 preset's convention plus a shoulder offset a1."""
    p = math.pi
    return [
        (0.0, k["d1"], k["a1"], -p / 2),
        (-p / 2, 0.0, k["a2"], 0.0),
        (0.0, 0.0, k["a3"], -p / 2),
        (0.0, k["d4"], 0.0, p / 2),
        (0.0, 0.0, 0.0, -p / 2),
        (p, k["d6"], 0.0, 0.0),
    ]


def fmt(x: float) -> str:
    return repr(float(np.round(x, 12)))


def urdf_text(name: str, origins, limits, inertials: dict[str, Inertial], header: str) -> str:
    lines = ['<?xml version="1.0"?>', header, f'<robot name="{name}">']
    for link in (*LINKS, "tool0"):
        lines.append(f'  <link name="{link}">')
        if link in inertials:
            b = inertials[link]
            i = b.inertia_array
            lines += [
                "    <inertial>",
                f'      <mass value="{fmt(b.mass)}"/>',
                f'      <origin xyz="{" ".join(fmt(v) for v in b.com)}" rpy="0 0 0"/>',
                f'      <inertia ixx="{fmt(i[0, 0])}" ixy="{fmt(i[0, 1])}" ixz="{fmt(i[0, 2])}" '
                f'iyy="{fmt(i[1, 1])}" iyz="{fmt(i[1, 2])}" izz="{fmt(i[2, 2])}"/>',
                "    </inertial>",
            ]
        lines.append("  </link>")
    for i in range(6):
        lo, hi, vel = limits[i]
        lines += [
            f'  <joint name="joint_{i + 1}" type="revolute">',
            f'    <parent link="{LINKS[i]}"/>',
            f'    <child link="{LINKS[i + 1]}"/>',
            f'    <origin xyz="{" ".join(fmt(v) for v in origins[i])}" rpy="0 0 0"/>',
            f'    <axis xyz="{AXES[i]}"/>',
            f'    <limit effort="0" lower="{fmt(lo)}" upper="{fmt(hi)}" velocity="{fmt(vel)}"/>',
            "  </joint>",
        ]
    lines += [
        '  <joint name="joint_6-tool0" type="fixed">',
        '    <parent link="link_6"/>',
        '    <child link="tool0"/>',
        f'    <origin xyz="0 0 0" rpy="0 {fmt(math.pi / 2)} 0"/>',
        "  </joint>",
        "</robot>",
    ]
    return "\n".join(lines) + "\n"


def mesh_inertials(
    repo: Path, meshes: dict[str, str], total_mass: float
) -> tuple[dict[str, Inertial], float]:
    props = {link: volume_properties(read_stl(git_show(repo, path))) for link, path in meshes.items()}
    for link, (vol, _, _) in props.items():
        assert vol > 0, (link, vol)
    density = total_mass / sum(p[0] for p in props.values())
    out = {link: Inertial.from_arrays(density * v, c, density * i) for link, (v, c, i) in props.items()}
    return out, density


def to_dh(urdf_path: Path, rows, link_inertials: dict[str, Inertial]) -> list[Inertial]:
    """Link inertials (URDF link frames) re-expressed in the DH link frames (as make_irb120_preset.py)."""
    chain = chain_from_urdf(urdf_path)
    urdf_frame, dh_frame = np.eye(4), np.eye(4)
    out = []
    for i in range(6):
        urdf_frame = urdf_frame @ chain.placements[i]
        dh_frame = dh_frame @ dh_transform(*rows[i])
        rel = np.linalg.inv(urdf_frame) @ dh_frame
        rot, t = rel[:3, :3], rel[:3, 3]
        b = link_inertials[LINKS[i + 1]]
        com = rot.T @ (b.com_array - t)
        inertia = rot.T @ b.inertia_array @ rot
        out.append(Inertial.from_arrays(b.mass, np.round(com, 12), np.round(inertia, 12)))
    return out


def irb140_inertials(k140: dict[str, float]) -> tuple[dict[str, Inertial], float, list[Inertial]]:
    """IRB 120 CAD inertials (DH frames) scaled to the IRB 140: masses to 98 kg in the IRB 120's
    proportions, centres of mass by the reach ratio, inertias by mass ratio x length ratio²."""
    d120 = preset_description("irb120")
    bodies = [d120.base, *(j.inertial for j in d120.joints)]
    assert all(b is not None for b in bodies)
    cad_total = sum(b.mass for b in bodies)  # type: ignore[union-attr]
    s = 0.81 / 0.58
    scaled = []
    for b in bodies:
        f = 98.0 / cad_total
        scaled.append(Inertial.from_arrays(b.mass * f, b.com_array * s, b.inertia_array * f * s * s))  # type: ignore[union-attr]
    return {"base_link": scaled[0]}, 98.0 / cad_total, scaled[1:]


def validate_on_irb120(repo: Path) -> dict[str, float]:
    """The mesh method applied to the IRB 120 against its CAD inertials (both scaled to 25 kg)."""
    text = git_show(repo, "abb_irb120_support/urdf/irb120_3_58_macro.xacro").decode()
    _, _, meshes = read_xacro(text)
    est, _ = mesh_inertials(repo, meshes, 25.0)
    d120 = preset_description("irb120")
    cad = [d120.base, *(j.inertial for j in d120.joints)]
    cad_total = sum(b.mass for b in cad)  # type: ignore[union-attr]
    errs = []
    for link, b in zip(LINKS[1:6], cad[1:6], strict=True):  # links 1-5: the ones that carry mass
        errs.append(est[link].mass / (b.mass * 25.0 / cad_total) - 1.0)  # type: ignore[union-attr]
    # centres of mass: the CAD ones in the URDF link frames (the bundled irb120.urdf) against the mesh's
    urdf = chain_from_urdf(PRESETS / "irb120.urdf")
    com_err = max(float(np.abs(urdf.coms[i] - est[LINKS[i + 1]].com_array).max()) for i in range(5))
    return {
        "max_link_mass_error": float(np.max(np.abs(errs))),
        "errors": errs,  # type: ignore[dict-item]
        "max_com_error": com_err / 0.302,  # of the IRB 120's longer arm (d4 = 302 mm)
    }


def collection_ranges(limits) -> RangeSet:
    """The ``collection`` range set (what ``simulate``/``rapid collect`` excite within): ASSUMED, the
    nominal ranges 10 deg inside each end, axes 4 and 6 within ±180 deg (cables), for a free cell."""
    margin = 10 * DEG
    lower, upper = [], []
    for i, (lo, hi, _) in enumerate(limits):
        lo, hi = lo + margin, hi - margin
        if i in (3, 5):
            lo, hi = max(lo, -math.pi), min(hi, math.pi)
        lower.append(float(np.round(lo, 12)))
        upper.append(float(np.round(hi, 12)))
    return RangeSet(name="collection", lower=tuple(lower), upper=tuple(upper))


def check_against_irb1200_urdf(repo: Path) -> float:
    """The mesh integral here against the inertials ROS-Industrial publishes for the IRB 1200-5/0.9
    (the one URDF of the range that has them: uniform density to 54 kg, computed by its authors with
    their own tool). Returns the largest relative difference of a link's mass or principal-axis
    moment (the base and links 1-5; their link 6 copies the IRB 120's flange)."""
    text = git_show(repo, "abb_irb1200_support/urdf/irb1200_5_90_macro.xacro").decode()
    _, _, meshes = read_xacro(text)
    est, _ = mesh_inertials(repo, meshes, 54.0)
    worst = 0.0
    for link in LINKS[:6]:
        block = re.search(r'<link name="\$\{prefix\}' + link + r'">(.*?)</link>', text, re.S)
        assert block
        found = re.search(r'mass value="([^"]+)"', block.group(1))
        assert found
        mass = float(found.group(1))
        moments = {k: float(v) for k, v in re.findall(r'(i[xyz]{2})="([^"]+)"', block.group(1))}
        inertia = est[link].inertia_array
        worst = max(worst, abs(est[link].mass / mass - 1))
        for key, rc in (("ixx", 0), ("iyy", 1), ("izz", 2)):
            worst = max(worst, abs(inertia[rc, rc] / moments[key] - 1))
    assert worst < 1e-3, worst
    return worst


# ---------------------------------------------------------------------------- writers


def toml_str(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--abb-experimental", type=Path, required=True)
    ap.add_argument("--abb", type=Path, required=True)
    args = ap.parse_args()
    repos = {"abb_experimental": args.abb_experimental, "abb": args.abb}
    heads = {k: git_head(v) for k, v in repos.items()}
    check = validate_on_irb120(repos["abb_experimental"])
    mass_bound = round(math.ceil(check["max_link_mass_error"] * 20) / 20 + 0.05, 2)
    print(
        f"mesh method on the IRB 120, link 1-5 mass errors: {np.round(check['errors'], 3)}; bound {mass_bound}"
    )
    agree = check_against_irb1200_urdf(repos["abb_experimental"])
    print(f"mesh integral against the IRB 1200-5/0.9 URDF's own inertials: largest difference {agree:.1e}")
    for v in VARIANTS:
        if v.repo:
            text = git_show(repos[v.repo], v.xacro).decode()
            origins, limits, meshes = read_xacro(text)
            src = f"ROS-Industrial {v.repo} @ {heads[v.repo]}, {v.xacro} (Apache-2.0)"
        else:
            origins = IRB140["origins"]
            limits = [
                (lo * DEG, hi * DEG, sp * DEG)
                for (lo, hi), sp in zip(IRB140["ranges_deg"], IRB140["speeds_deg_s"], strict=True)
            ]
            meshes = {}
            src = (
                "ABB data sheet IRB 140 (dimension drawing, axis working range, axis max speed), values as "
                "written in scripts/make_abb_presets.py, not re-read from ABB's document there; the lengths "
                "agree with FreddyMartinez/abb_irb140_support's URDF (no licence stated: numbers compared only)"
            )
        k = dh_params(origins)
        rows = dh_rows(k)
        com_bound = round(0.1 * max(k["a2"], k["d4"]), 3)
        if meshes:
            link_inertials, density = mesh_inertials(repos[v.repo], meshes, v.mass_kg)
            how = (
                f"the link's collision mesh of {src.split(',')[0]} ({meshes['link_2'].rsplit('/', 2)[0]}/) at "
                f"one uniform density, {density:.0f} kg/m³, chosen so that base and links weigh the "
                f"catalogue mass {v.mass_kg:g} kg"
            )
        else:
            link_inertials, _, dh_links = irb140_inertials(k)
            how = (
                "the IRB 120's CAD inertials (ROS-Industrial abb_experimental irb120_3_58, Apache-2.0) "
                "scaled: masses to the IRB 140's catalogue mass 98 kg in the IRB 120's proportions, "
                "centres of mass by the reach ratio 0.81/0.58, inertias by mass ratio times length ratio²"
            )
        header = (
            f"<!-- ABB {v.abb_name}: kinematics and limits from {src}; link inertials ESTIMATED by "
            "scripts/make_abb_presets.py (see the .provenance.toml beside this file); no meshes. -->"
        )
        urdf_path = PRESETS / f"{v.id}.urdf"
        if meshes:
            urdf_path.write_text(urdf_text(v.id, origins, limits, link_inertials, header))
            dh_links = to_dh(urdf_path, rows, link_inertials)
        else:
            # express the scaled DH-frame inertials in URDF link frames for the URDF twin
            urdf_path.write_text(urdf_text(v.id, origins, limits, {}, header))
            chain = chain_from_urdf(urdf_path)
            uf, df = np.eye(4), np.eye(4)
            for i in range(6):
                uf = uf @ chain.placements[i]
                df = df @ dh_transform(*rows[i])
                rel = np.linalg.inv(uf) @ df
                rot, t = rel[:3, :3], rel[:3, 3]
                b = dh_links[i]
                link_inertials[LINKS[i + 1]] = Inertial.from_arrays(
                    b.mass, rot @ b.com_array + t, rot @ b.inertia_array @ rot.T
                )
            urdf_path.write_text(urdf_text(v.id, origins, limits, link_inertials, header))
            dh_links = to_dh(urdf_path, rows, link_inertials)
        joints = []
        for i, (off, d, r, alpha) in enumerate(rows):
            lo, hi, vel = limits[i]
            joints.append(
                JointDescription(
                    id=i + 1, type="T" if i in (0, 3, 5) else "R", xi=1, variable=f"q{i + 1}", offset=off,
                    d=float(np.round(d, 12)), r=float(np.round(r, 12)), alpha=alpha, inertial=dh_links[i],
                    lower=float(np.round(lo, 12)), upper=float(np.round(hi, 12)), velocity=float(np.round(vel, 12)),
                )
            )  # fmt: skip
        desc = RobotDescription(
            name=v.abb_name,
            manufacturer="ABB",
            info=(
                ("variant", v.abb_name),
                ("carrying-capacity", repr(v.payload_kg)),
                ("reach", repr(v.reach_m)),
                ("configuration", "Articulated"),
                ("ir-type", "Serial"),
                ("manipulator-mass", repr(v.mass_kg)),
                ("joint-zero", "ABB: q = 0 is the calibration (home) pose"),
                ("frames", "center and inertia in the link's DH frame; inertia about the COM"),
                (
                    "model",
                    f"estimated: link masses ±{mass_bound:.0%}, centres of mass ±{com_bound * 1000:.0f} mm, inertias "
                    f"±{mass_bound:.0%} (ESTIMATES; sources and bounds in {v.id}.provenance.toml)",
                ),
                *((("family-default", v.family),) if v.default else ()),
                ("source/kinematics", src),
                ("source/limits", src),
                ("source/dynamics", "ESTIMATED from " + how),
            ),
            joints=tuple(joints),
            base=link_inertials["base_link"],
            range_sets=(collection_ranges(limits),),
        )
        desc = replace(desc, info=(*desc.info, ("model-fingerprint", dynamics_fingerprint(desc))))
        (PRESETS / f"{v.id}.irml").write_text(irml_string(desc))
        params = [
            ("kinematics", "published", src, "DH lengths d1, a1, a2, a3, d4, d6 read from the joint origins", "0.5 mm"),
            ("axis ranges", "published", src, "as the source gives them", "exact as published"),
            ("axis speeds", "published", src, "as the source gives them", "exact as published"),
            (
                "manipulator mass",
                "published",
                f"ABB data sheet {v.abb_name}",
                "the catalogue value (not re-read from ABB's document when written here)",
                f"±{CATALOGUE_BOUND:.0%}",
            ),
            ("rated payload, reach", "published", f"ABB data sheet {v.abb_name}", "the variant's name", "exact"),
            ("link masses", "estimated", "scripts/make_abb_presets.py", how, f"±{mass_bound:.0%} each"),
            ("centres of mass", "estimated", "scripts/make_abb_presets.py", how, f"±{com_bound} m per axis"),
            ("inertias", "estimated", "scripts/make_abb_presets.py", how + "; scaled with the link's mass", f"±{mass_bound:.0%}"),
            (
                "collection range set",
                "assumed",
                "scripts/make_abb_presets.py",
                "the nominal ranges 10 deg inside each end, axes 4 and 6 within ±180 deg: an excitation "
                "envelope for a free cell; narrow it to your cell",
                "a choice, not a fact",
            ),
            ("torque limits", "assumed", "none public", "not given: the torque check is skipped", "unknown"),
            ("friction", "assumed", "none public", "rigid body only (no friction) until identified", "unknown"),
        ]  # fmt: skip
        lines = [
            f"# {v.abb_name}: where each parameter of {v.id}.irml comes from, and how sure it is.",
            "# Written by scripts/make_abb_presets.py; read by joulepath.description.read_provenance.",
            f"robot = {toml_str(v.id)}",
            f"name = {toml_str(v.abb_name)}",
            f"family = {toml_str(v.family)}",
            f"family_default = {'true' if v.default else 'false'}",
            'status = "estimated"',
            "notes = [",
            '  "the axis-2 balancing device (spring or hydraulic cylinder) of the large arms is not modelled: '
            'the axis-2 torque and energy are overstated where it carries the arm",',
            f'  "mesh method checked on the IRB 120 (its ROS-I CAD inertials): link 1-5 masses off by '
            f"{', '.join(f'{e:+.0%}' for e in check['errors'])}, hence the bound; centres of mass off by at most "
            f"{check['max_com_error']:.0%} of the arm length, hence a bound of 10 % of the longer arm; link 6 (the "
            'flange, under 1 % of the mass) is not estimated well by its collision mesh",',
            '  "what the bound does not cover: the IRB 120 reference is itself a CAD estimate of undocumented '
            "origin (its links and base weigh 18.1 kg against the catalogue's 25 kg), so the check measures the "
            "collision mesh against CAD geometry, not a real arm's uneven density (motors and gears are denser "
            "than castings); no public measurement of these arms' link masses exists to bound that\",",
            f'  "the mesh integral reproduces the inertials that ROS-Industrial publishes for the IRB 1200-5/0.9 '
            f'(the same method, their own tool) to {agree:.0e} (largest relative difference, base and links 1-5)",',
            *(
                ()
                if meshes
                else (
                    "  \"the IRB 140 has no licensed public mesh: its link dynamics are the IRB 120's scaled, a "
                    "method not checked against a known arm; the bound is the mesh method's\",",
                )
            ),
            "]",
            "",
            "[uncertainty]",
            f"link_mass_rel = {mass_bound}",
            f"link_com_m = {com_bound}",
            f"link_inertia_rel = {mass_bound}",
            f"catalogue_mass_rel = {CATALOGUE_BOUND}",
        ]
        for name, kind, source, how_, bound in params:
            lines += [
                "",
                "[[parameter]]",
                f"name = {toml_str(name)}",
                f"kind = {toml_str(kind)}",
                f"source = {toml_str(source)}",
                f"how = {toml_str(how_)}",
                f"bound = {toml_str(bound)}",
            ]
        (PRESETS / f"{v.id}.provenance.toml").write_text("\n".join(lines) + "\n")
        total = desc.base.mass + sum(j.inertial.mass for j in desc.joints)  # type: ignore[union-attr]
        print(f"{v.id}: {k} total mass {total:.1f} kg")


if __name__ == "__main__":
    main()
