"""Identification judged on real logs: a KUKA KR300 twin from one part of its excitation, its joint
torques predicted on a run held out (issue 50, item 2).

Data: the KUKA KR300 R2500 ultra logs of Weigand et al. (github.com/JonasWeigand/Robot_Identification,
MIT; ``--data`` folder, default ``../shared/datasets/kuka-kr300-weigand`` beside the repository):
three excitation runs (A, B, C) of 10 s at 250 Hz, motor-encoder positions and speeds (joint
side) and motor torques; the joint-side torque as the drives see it is the motor torque times
the gear ratio ``para.u``.

The robot: a URDF written here from the Denavit-Hartenberg table, masses, centres of mass and
inertias of that repository's ``robot_model/model_KUKA_Quantec_Ultra_KR300.m`` (standard DH as
in Corke's toolbox, base rotated 180° about x, joint 3 offset 90°, 200 kg payload on axis 6):
the nominal description and the prior of the parameters the runs leave unexcited. The arm's
hydraulic weight counterbalance on axis 2 is not in that model (nor in joulepath's): its torque
is left to the identified gravity terms of link 2, which can only approximate it.

For each run held out, ``joulepath identify`` (library form, defaults: gear efficiency
estimated, friction with offset, unexcited parameters kept at the prior) on the other two runs,
then ``joulepath evaluate`` on the held-out run: the per-joint R² of the torque. Writes the
``identify_real`` section of BENCHMARKS.md.

Second arm, when ``--panda FOLDER`` is given: the Franka Emika Panda excitation of Gaz et al.
(github.com/marcocognetti/FrankaEmikaPandaDynModel, GPL-3.0, so never copied into this
repository: FOLDER holds that repository's
``matlab/data/Exciting_Traj/Trajectory_1/rbt_log/exciting_traj_{time,positions,velocity,torques}.txt``),
21 s at 1 kHz of joint positions, speeds and joint-torque-sensor readings (joint side, so the
gear efficiency is fixed at 1). The named arm ``panda`` (example-robot-data, hand locked) is
the nominal robot; the twin is identified on the first 60 % of the excitation and its torques
predicted on the last 40 %.

Each arm is judged twice, by the library's option for deriving the motion from a log
(``data_from_logs(speed_cutoff_hz=...)``, ``EvaluateConfig(speed_cutoff_hz=...)``, ``--speed-cutoff``
on the command line): raw (``off``: the central difference of the logged speeds), and ``auto``,
the command line's default (20 Hz for a log of 200 Hz or more: both arms here), which low-passes
the logged speeds (4th-order Butterworth, zero phase, on a uniform time base, repeated rows left
out) before differentiating them, the identification part and the held-out motion alike, never the
held-out torque. The Panda log's timestamps jitter (0.7 to 1.9 ms between rows of a 1 kHz log) and
6 % of its rows repeat the one before, so the central difference of its raw speeds is a noisy
acceleration, which joint 1 (turning about the vertical, no gravity torque, its torque mostly
inertial) cannot afford.

Identification uses the defaults, the armature per joint included (``IdentifyOptions.armature``).

Each arm is identified twice: with the defaults (the physically consistent refinement) and
with the least-squares base parameters only (``consistent=False``), to show what the
refinement costs on real data.

With ``--study``, the KR300 alone through a ladder of refinements instead, each measured as
the held-out torque R² per joint (each run held out in turn, the raw logged torque as the
reference), least squares and physically consistent: the viscous level per direction
(``viscous_offset``), a sharper Coulomb switch (``smoothing``), a Stribeck term, a time shift
between the torque and the motion signals (the torque column moved by whole samples), and the
library's zero-phase low-pass of the logged speed before its differentiation (``speed_cutoff_hz``;
identification and held-out motion alike; never the held-out torque). Writes the
``identify_real_study`` section.

Usage: python benchmarks/identify_real.py [--data FOLDER] [--panda FOLDER] [--study]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_core, write_section  # noqa: E402

single_core()

import numpy as np  # noqa: E402

import joulepath  # noqa: E402
from joulepath.identify import (  # noqa: E402
    EvaluateConfig,
    IdentifyOptions,
    UnexcitedParameterWarning,
    data_from_logs,
    evaluate_model,
    identify,
    r2_per_joint,
    write_twin,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from unknown_arm import DEFAULT_DATA, RUNS, write_generic_log  # noqa: E402

# (d, a, alpha, offset) of each link (m, rad), standard DH; mass (kg), centre of mass in the link frame
# (m), inertia about it [Ixx, Iyy, Izz, Ixy, Iyz, Ixz] (kg m²): model_KUKA_Quantec_Ultra_KR300.m
DH = (
    (-0.675, 0.350, np.pi / 2, 0.0),
    (-0.189, 1.15, 0.0, 0.0),
    (0.189, 0.041, -np.pi / 2, np.pi / 2),
    (-1.0, 0.0, np.pi / 2, 0.0),
    (0.0, 0.0, -np.pi / 2, 0.0),
    (-0.24, 0.0, np.pi, 0.0),
)
MASS = (395.40, 339.12, 105.21, 35.80, 31.46, 200.0 + 17.78)
COM = (
    (-0.353, 0.174, -0.004),
    (-0.709, -0.001, 0.023),
    (-0.018, -0.018, -0.076),
    (0.0, 0.236, 0.001),
    (0.0, -0.080, -0.009),
    (0.0, 0.0, (200.0 * 0.100 + 17.78 * -0.050) / 217.78),
)
INERTIA = (
    (16.733765, 29.799119, 32.814954, -1.703664, 0.129384, 4.404062),
    (7.507819, 88.886691, 88.673761, 0.430046, 0.173157, -4.396607),
    (10.783798, 10.186135, 1.943179, 0.118474, -0.606384, -0.101950),
    (0.425035, 0.217993, 0.428465, -0.000004, -0.011353, -0.000027),
    (0.283826, 0.229562, 0.258266, -0.000004, -0.019521, -0.000120),
    (0.5, 0.5, 0.5, 0.0, 0.0, 0.0),  # not given (a point mass there): a small placeholder
)
START_DEG = (0.0, -90.0, 90.0, 0.0, 0.0, 0.0)
"""The runs' start pose (the logs give positions from it): KUKA's home, in the DH model's angles. Checked
by its holding torques: the model's gravity there, (0, -3490, -3494, -25, -703, 0) N·m, against the
logged (539, -756, -4193, -53, -489, 1) N·m at the first sample (joint 2: the counterbalance carries
the difference)."""
LIMITS_DEG = ((-147, 147), (-140, -5), (-112, 153), (-350, 350), (-122.5, 122.5), (-350, 350))


def _rpy(R: np.ndarray) -> tuple[float, float, float]:
    import pinocchio as pin

    r, p, y = pin.rpy.matrixToRpy(R)
    return float(r), float(p), float(y)


def _dh(d: float, a: float, alpha: float, offset: float) -> np.ndarray:
    """Rz(offset) Tz(d) Tx(a) Rx(alpha): from the frame the joint turns to the DH link frame."""
    c, s, ca, sa = np.cos(offset), np.sin(offset), np.cos(alpha), np.sin(alpha)
    return np.array([[c, -s * ca, s * sa, a * c], [s, c * ca, -c * sa, a * s], [0, sa, ca, d], [0, 0, 0, 1]])


def kr300_urdf() -> str:
    """The KR300 as a URDF: link i's frame turns with joint i; the DH link frame follows it."""

    def origin(T: np.ndarray) -> str:
        x, y, z = (float(v) for v in T[:3, 3])
        r, p, w = _rpy(T[:3, :3])
        return f'<origin xyz="{x!r} {y!r} {z!r}" rpy="{r!r} {p!r} {w!r}"/>'

    base = np.diag([1.0, -1.0, -1.0, 1.0])  # trotx(180 deg)
    parts = ['<robot name="kr300_r2500_ultra">', '<link name="base"/>']
    parent, before = "base", base
    for i, (dh, m, com, inertia, (lo, hi)) in enumerate(zip(DH, MASS, COM, INERTIA, LIMITS_DEG, strict=True)):
        A = _dh(*dh)
        ixx, iyy, izz, ixy, iyz, ixz = inertia
        I_dh = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        c = A[:3, :3] @ np.asarray(com) + A[:3, 3]
        I_link = A[:3, :3] @ I_dh @ A[:3, :3].T
        parts.append(
            f'<link name="link{i + 1}"><inertial><origin xyz="{float(c[0])!r} {float(c[1])!r} {float(c[2])!r}" rpy="0 0 0"/>'
            f'<mass value="{m!r}"/><inertia ixx="{float(I_link[0, 0])!r}" ixy="{float(I_link[0, 1])!r}" '
            f'ixz="{float(I_link[0, 2])!r}" iyy="{float(I_link[1, 1])!r}" iyz="{float(I_link[1, 2])!r}" izz="{float(I_link[2, 2])!r}"/>'
            "</inertial></link>"
        )
        parts.append(
            f'<joint name="a{i + 1}" type="revolute"><parent link="{parent}"/><child link="link{i + 1}"/>'
            f'{origin(before)}<axis xyz="0 0 1"/><limit lower="{float(np.radians(lo))!r}" upper="{float(np.radians(hi))!r}" '
            'velocity="2.0" effort="0"/></joint>'
        )
        parent, before = f"link{i + 1}", A
    tool = before @ np.array([[0.0, 0, -1, 0], [0, 1, 0, 0], [1, 0, 0, 0], [0, 0, 0, 1]])  # troty(-90 deg)
    parts.append(
        f'<joint name="flange" type="fixed"><parent link="link6"/><child link="tool0"/>{origin(tool)}</joint>'
    )
    parts.append('<link name="tool0"/></robot>')
    return "\n".join(parts)


CUTOFFS: tuple[tuple[str, float | str | None], ...] = (("off", None), ("auto", "auto"))
"""How the motion is derived from the logs in the main table: raw, and the command line's default."""


def write_panda_logs(folder: Path, out: Path, share: float = 0.6) -> tuple[Path, Path]:
    """The Panda excitation as two generic joint logs: the first ``share`` and the rest."""
    t = np.loadtxt(folder / "exciting_traj_time.txt")
    n = t.size
    q, qd, tau = (
        np.loadtxt(folder / f"exciting_traj_{k}.txt").reshape(n, 7)
        for k in ("positions", "velocity", "torques")
    )
    header = ",".join(["t", *(f"{p}{i}" for i in range(1, 8) for p in ("q", "dq", "tau"))])
    cut = int(share * n)
    paths = []
    for name, part in (("ident", slice(0, cut)), ("valid", slice(cut, n))):
        cols = [t[part] - t[part][0], *(a[part, i] for i in range(7) for a in (q, qd, tau))]
        path = out / f"panda_{name}.csv"
        np.savetxt(path, np.column_stack(cols), delimiter=",", header=header, comments="", fmt="%.9g")
        paths.append(path)
    return paths[0], paths[1]


def judge(
    robot: joulepath.Robot,
    ident_logs: list[Path],
    valid: Path,
    options: IdentifyOptions,
    twin: Path,
    cutoff: float | str | None = None,
) -> dict:
    """Identify on ``ident_logs``; with the consistent refinement write the twin and ``evaluate`` it on
    ``valid``; without it (parameters that need not be physical, so no twin a robot can be built
    from) score the identification's own prediction on ``valid``. ``cutoff``: the library's
    ``speed_cutoff_hz`` for the identification and the held-out motion alike."""
    data = data_from_logs(ident_logs, robot, speed_cutoff_hz=cutoff)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UnexcitedParameterWarning)
        ident = identify(data, robot, options)
    if options.consistent:
        write_twin(ident, robot, twin)
        config = EvaluateConfig(speed_cutoff_hz=cutoff)
        ev = evaluate_model(valid, joulepath.load_robot(twin), robot_source=str(twin), config=config)
        r2 = ev.summary()["torque"]["r2"]
    else:
        held = data_from_logs([valid], robot, speed_cutoff_hz=cutoff)
        r2 = r2_per_joint(held.tau, ident.motor_torque(robot, held.q, held.qd, held.qdd)).tolist()
    return {
        "fit": ident.fit.torque_r2,
        "r2": r2,
        "mean": float(np.mean([v for v in r2 if v is not None])),
        "eta": ident.gear_efficiency,
        "cond": ident.condition_number,
        "kept": [k.name for k in ident.kept],
        "warned": len(caught),
        "consistent": ident.consistent,
        "motion": data.motion.describe() if data.motion is not None else "",
        "cutoff_hz": data.motion.cutoff_hz if data.motion is not None else (),
    }


def reshaped_log(log: Path, out: Path, *, shift: int = 0) -> Path:
    """A generic log with its torques moved ``shift`` samples later in time (the torque logged at
    sample ``k + shift`` paired with the motion of sample ``k``)."""
    import pandas as pd

    frame = pd.read_csv(log)
    taus = [c for c in frame.columns if c.startswith("tau")]
    if shift:
        frame[taus] = frame[taus].shift(-shift)
        frame = frame.dropna().reset_index(drop=True)
    frame.to_csv(out, index=False, float_format="%.10g")
    return out


STUDY: tuple[tuple[str, dict[str, object], int, float | None], ...] = (
    ("defaults (Coulomb + viscous + offset, smoothing 0.005 rad/s)", {}, 0, None),
    ("+ viscous per direction", {"viscous_offset": True}, 0, None),
    (
        "+ sharper Coulomb switch (smoothing 0.0002 rad/s)",
        {"viscous_offset": True, "smoothing": 2e-4},
        0,
        None,
    ),
    (
        "+ Stribeck term (0.01 rad/s)",
        {"viscous_offset": True, "smoothing": 2e-4, "stribeck_speed": 0.01},
        0,
        None,
    ),
    (
        "+ torque 1 sample (4 ms) later",
        {"viscous_offset": True, "smoothing": 2e-4, "stribeck_speed": 0.01},
        1,
        None,
    ),
    (
        "+ torque 1 sample (4 ms) earlier",
        {"viscous_offset": True, "smoothing": 2e-4, "stribeck_speed": 0.01},
        -1,
        None,
    ),
    (
        "+ speeds low-passed at 20 Hz before differentiation",
        {"viscous_offset": True, "smoothing": 2e-4, "stribeck_speed": 0.01},
        0,
        20.0,
    ),
    (
        "+ speeds low-passed at 10 Hz before differentiation",
        {"viscous_offset": True, "smoothing": 2e-4, "stribeck_speed": 0.01},
        0,
        10.0,
    ),
)


def study(args: argparse.Namespace) -> None:
    """The KR300 through the ladder of :data:`STUDY`: held-out torque R² per joint of each step."""
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        urdf = d / "kr300.urdf"
        urdf.write_text(kr300_urdf())
        robot = joulepath.load_robot(urdf)
        raw = {
            r: write_generic_log(args.data / f"recorded_FF_{r}.mat", d / f"kr300_{r}.csv", START_DEG)
            for r in RUNS
        }
        for k, (label, extra, shift, cutoff) in enumerate(STUDY):
            logs = {r: reshaped_log(raw[r], d / f"s{k}_{r}.csv", shift=shift) for r in RUNS}
            for consistent in (False, True):
                options = IdentifyOptions(consistent=consistent, **extra)  # type: ignore[arg-type]
                per_run = [
                    judge(
                        robot,
                        [logs[r] for r in RUNS if r != held],
                        logs[held],
                        options,
                        d / f"t{k}{held}",
                        cutoff,
                    )
                    for held in RUNS
                ]
                r2 = np.array([p["r2"] for p in per_run], dtype=float)
                rows.append(
                    {
                        "step": label,
                        "how": "physically consistent" if consistent else "least squares",
                        "per_joint": r2.mean(axis=0),
                        "per_run": r2.mean(axis=1),
                        "mean": float(r2.mean()),
                        "consistent": all(p["consistent"] for p in per_run) if consistent else None,
                    }
                )
                print(rows[-1], flush=True)
    lines = [
        "## Identification on real logs, refinements one by one: KUKA KR300 (benchmarks/identify_real.py --study)",
        "",
        f"Machine: {machine()}. Data: KUKA KR300 R2500 ultra, Weigand et al. (MIT), three 10 s excitation "
        "runs at 250 Hz; each run held out in turn, the twin identified on the other two; R² of the held-out "
        "run's raw logged joint torque (motor torque x gear ratio), per joint averaged over the three runs. "
        "Each step adds to the one above (the shifts and filters each to the Stribeck step); every step "
        "with the armature per joint (`IdentifyOptions.armature`, the default); the filters are the "
        "library's (`speed_cutoff_hz`), every other step differentiates the raw speeds (`--speed-cutoff off`).",
        "",
        "| step | identified with | held-out torque R² per joint (mean of 3 runs) | mean | per held-out run (A, B, C) |",
        "|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['step']} | {r['how']} | {', '.join(f'{v:.3f}' for v in r['per_joint'])} | {r['mean']:.3f} | "
            f"{', '.join(f'{v:.3f}' for v in r['per_run'])} |"
        )
    write_section("identify_real_study", "\n".join(lines))
    print("\n".join(lines))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA)
    parser.add_argument("--panda", type=Path, default=None)
    parser.add_argument("--study", action="store_true", help="the KR300 through the refinements one by one")
    args = parser.parse_args()
    if args.study:
        study(args)
        return
    rows = []
    settings = {"defaults": IdentifyOptions(), "least squares only": IdentifyOptions(consistent=False)}
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        urdf = d / "kr300.urdf"
        urdf.write_text(kr300_urdf())
        robot = joulepath.load_robot(urdf)
        logs = {
            r: write_generic_log(args.data / f"recorded_FF_{r}.mat", d / f"kr300_{r}.csv", START_DEG)
            for r in RUNS
        }
        for held in RUNS:
            for name, cutoff in CUTOFFS:
                for label, options in settings.items():
                    result = judge(
                        robot,
                        [logs[r] for r in RUNS if r != held],
                        logs[held],
                        options,
                        d / f"twin-{held}-{label}-{name}",
                        cutoff,
                    )
                    rows.append(
                        {"arm": "KUKA KR300", "held": f"run {held}", "how": label, "speeds": name, **result}
                    )
                    print(rows[-1], flush=True)
        if args.panda is not None:
            panda = joulepath.load_robot("panda")
            ident_log, valid_log = write_panda_logs(args.panda, d)
            for name, cutoff in CUTOFFS:
                for label, options in settings.items():
                    options = IdentifyOptions(gear_efficiency=1.0, consistent=options.consistent)
                    result = judge(
                        panda, [ident_log], valid_log, options, d / f"twin-panda-{label}-{name}", cutoff
                    )
                    rows.append(
                        {"arm": "Franka Panda", "held": "last 40 %", "how": label, "speeds": name, **result}
                    )
                    print(rows[-1], flush=True)
    lines = [
        "## Identification on real logs: KUKA KR300 (benchmarks/identify_real.py)",
        "",
        f"Machine: {machine()}. Data: KUKA KR300 R2500 ultra, Weigand et al. (MIT), three 10 s "
        "excitation runs at 250 Hz, joint torque = motor torque x gear ratio; nominal robot and prior: "
        "the DH model of that repository (no hydraulic counterbalance). Twin identified on two runs, "
        "torques of the third predicted (`evaluate`). Franka Panda (with `--panda`): Gaz et al. "
        "(GPL-3.0, used locally, not in the repository), 21 s excitation at 1 kHz, joint torque sensors; "
        "identified on the first 60 %, predicted on the last 40 %; nominal robot: the named arm `panda`. "
        "Speeds: `off`, the central difference of the raw logged speeds; `auto` (the command line's "
        "default), the library's low-pass of the logged speeds before differentiation "
        "(`speed_cutoff_hz`; 20 Hz on both arms' logs, 250 Hz and 1 kHz), identification and held-out "
        "motion alike; the held-out torque always raw. Every fit with an armature per joint "
        "(`IdentifyOptions.armature`, the default).",
        "",
        "| arm | held out | identified with | speeds | torque R² per joint (held out) | mean | fit R² per joint | "
        "gear eff. | cond. | consistent | kept at prior |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        held_out = ", ".join("n/a" if v is None else f"{v:.3f}" for v in r["r2"])
        fit = ", ".join(f"{v:.3f}" for v in r["fit"])
        kept = ", ".join(r["kept"]) or "none"
        cut = "/".join(sorted({"raw" if c is None else f"{c:g} Hz" for c in r["cutoff_hz"]}))
        lines.append(
            f"| {r['arm']} | {r['held']} | {r['how']} | {r['speeds']} ({cut}) | {held_out} | {r['mean']:.3f} | "
            f"{fit} | {r['eta']:.3f} | {r['cond']:.0f} | {r['consistent']} | {kept} |"
        )
    lines += ["", "Means over the KR300's three held-out runs:", ""]
    for name, _ in CUTOFFS:
        for label in settings:
            sel = [r for r in rows if r["arm"] == "KUKA KR300" and r["speeds"] == name and r["how"] == label]
            if sel:
                per_joint = np.mean([r["r2"] for r in sel], axis=0)
                lines.append(
                    f"- speeds {name}, {label}: per joint {', '.join(f'{v:.3f}' for v in per_joint)}, "
                    f"mean {float(np.mean(per_joint)):.3f}"
                )
    write_section("identify_real", "\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
