# ruff: noqa: E501  (the case table keeps one line per case)
"""A hostile-input corpus through the real CLI (issue 15, item 1).

One line per case: ``(id, argv, expected exit code, message fragment, files)``. The
files are small literal contents written into ``{in}`` before the run; ``{out}`` is an
output path that must not exist afterwards when the exit code is 2. Every case must
end with either valid output (exit 0, the fragment on stdout) or exit 2 with exactly
one line on stderr that holds the fragment, no traceback, nothing written and the
inputs unchanged. Families of cases (each TOML key x each bad value, each IRML tag x
each bad number, ...) are generated, but each case is a distinct input.

Cases that fail today because of a defect in a part of joulepath that this corpus
does not own are marked ``xfail(strict=True, reason="owned by ...")``: the mark must
go once the defect is fixed. A sample runs in real processes to check that the exit
code is never negative or >= 128 (no segfault) and that no traceback is printed.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from joulepath.cli import main

# --------------------------------------------------------------------------- literal inputs


def _irml_joint(i: int) -> str:
    return (
        f'<joint id="{i}"><type>R</type><xi>1</xi>'
        f"<kinematics><q>q{i}</q><d>0.1</d><r>0.05</r><a>-pi/2</a></kinematics>"
        "<dynamics><link-mass>1.5</link-mass><center><x>0</x><y>0</y><z>0.02</z></center>"
        "<inertia><xx>0.01</xx><xy>0</xy><xz>0</xz><yx>0</yx><yy>0.01</yy><yz>0</yz>"
        "<zx>0</zx><zy>0</zy><zz>0.01</zz></inertia></dynamics>"
        "<limits><lower>-pi</lower><upper>pi</upper><velocity>4</velocity><effort>50</effort></limits>"
        "</joint>"
    )


IRML = (
    "<robot><name>Six</name><manufacturer>Test</manufacturer><reach>0.6</reach>"
    + "".join(_irml_joint(i) for i in range(1, 7))
    + "</robot>"
)


def _urdf_joint(i: int) -> str:
    axis = "0 0 1" if i % 2 else "0 1 0"
    return (
        f'<link name="l{i}"><inertial><mass value="1.5"/><origin xyz="0 0 0.02" rpy="0 0 0"/>'
        f'<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>'
        f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
        f'<origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="{axis}"/>'
        f'<limit lower="-3" upper="3" velocity="4" effort="50"/></joint>'
    )


URDF = (
    '<?xml version="1.0"?><robot name="six"><link name="l0"/>'
    + "".join(_urdf_joint(i) for i in range(1, 7))
    + '<link name="tool0"/><joint name="t" type="fixed"><parent link="l6"/><child link="tool0"/></joint>'
    + "</robot>"
)


def _log(n: int = 60, *, joints: int = 6, dt: float = 0.025, scale: float = 0.3) -> str:
    """A generic joint log (t, q, dq, tau per joint) of a smooth move, as text."""
    t = np.arange(n) * dt
    cols: dict[str, Any] = {"t": t}
    for i in range(1, joints + 1):
        w = i / (n * dt)
        cols |= {
            f"q{i}": scale * np.sin(w * t),
            f"dq{i}": scale * w * np.cos(w * t),
            f"tau{i}": 1.0 + 0.1 * i * np.sin(w * t),
        }
    lines = [",".join(cols)] + [",".join(f"{cols[k][r]:.6f}" for k in cols) for r in range(n)]
    return "\n".join(lines) + "\n"


LOG = _log()
LOG_LINES = LOG.splitlines()
HEADER = LOG_LINES[0].split(",")


def _log_cell(row: int, col: str, value: str) -> str:
    """LOG with one field (data line ``row``, column ``col``) replaced."""
    lines = list(LOG_LINES)
    cells = lines[row].split(",")
    cells[HEADER.index(col)] = value
    lines[row] = ",".join(cells)
    return "\n".join(lines) + "\n"


TOML = """\
name = "corpus"
seed = 1

[data]
train_moves = 3
test_moves = 2

[train]
families = ["par"]
cv = 2

[optimize]
tasks = 1
generations = 2
population = 4
"""


def _toml_set(section: str, key: str, value: str) -> str:
    """TOML with ``key = value`` in ``[section]`` (top level when ""), replacing the key if it is there."""
    lines, current = [], ""
    for line in TOML.splitlines():
        if line.startswith("["):
            current = line.strip("[]")
        if current == section and line.startswith(f"{key} = "):
            continue
        lines.append(line)
    text = "\n".join(lines) + "\n"
    if not section:
        return f"{key} = {value}\n" + text
    head = f"[{section}]\n"
    return (
        text.replace(head, head + f"{key} = {value}\n")
        if head in text
        else text + head + f"{key} = {value}\n"
    )


LOOP_MOD = """MODULE P
    CONST jointtarget J{2} := [[[10, 0, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]],
        [[20, 5, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]]];
    VAR num n := 2;
    PROC main()
        FOR k FROM 1 TO 2 DO
            MoveAbsJ J{k}, v1000, fine, tool0;
        ENDFOR
    ENDPROC
ENDMODULE
"""
OPT = "optimize --start 0,0,0,0,0,0 --end 0.5,0,0,0,0,0 --duration 1 --generations 1 --population 4"
MODEL = "@model"  # files key: copy the trained model folder to {in}/m first

# --------------------------------------------------------------------------- the table


def C(
    case_id: str,
    argv: str,
    rc: int,
    needle: str,
    files: dict[str, str | bytes] | None = None,
    owner: str | None = None,
) -> Any:
    """One case; ``owner`` marks a known defect elsewhere (strict xfail: remove once fixed)."""
    marks = [pytest.mark.xfail(strict=True, reason=f"owned by {owner}")] if owner else []
    return pytest.param(argv, rc, needle, files or {}, id=case_id, marks=marks)


IRML_TAGS_MISSING = [
    "type",
    "xi",
    "kinematics",
    "q",
    "d",
    "r",
    "a",
    "dynamics",
    "link-mass",
    "center",
    "inertia",
]
IRML_NUMBERS = {"d": "0.1", "r": "0.05", "link-mass": "1.5", "z": "0.02", "xx": "0.01", "velocity": "4"}
BAD_NUMBERS = {
    "text": "abc",
    "nan": "nan",
    "overflow": "1e999",
    "complex": "(-1)**0.5",
    "empty": "",
    "call": "__import__('os')",
    "deep": "(" * 150 + "1" + ")" * 150,
    "two-vars": "q1*q2",
}


def _irml_first(tag: str, value: str) -> str:
    return IRML.replace(f"<{tag}>{IRML_NUMBERS[tag]}</{tag}>", f"<{tag}>{value}</{tag}>", 1)


URDF_ATTRS = {
    "origin-xyz": ('xyz="0 0 0.1"', 'xyz="{}"'),
    "axis-xyz": ('<axis xyz="0 0 1"/>', '<axis xyz="{}"/>'),
    "mass": ('<mass value="1.5"/>', '<mass value="{}"/>'),
    "limit-lower": ('lower="-3"', 'lower="{}"'),
    "inertia-ixx": ('ixx="0.01"', 'ixx="{}"'),
}
BAD_URDF_VALUES = {"text": "abc", "nan": "nan nan nan", "inf": "inf 0 0", "short": "1", "hex": "0x10 0 0"}

INT_KEYS = {
    ("", "seed"): (0, 2**32 - 1),
    ("", "jobs"): (1, 256),
    ("data", "train_moves"): (1, 20_000),
    ("data", "test_moves"): (1, 20_000),
    ("data", "micro_moves"): (0, 20_000),
    ("data", "sim_moves"): (0, 20_000),
    ("synth", "rows"): (1, 1_000_000),
    ("synth", "epochs"): (1, 10_000),
    ("synth", "batch_size"): (2, 100_000),
    ("train", "cv"): (2, 20),
    ("importance", "max_rows"): (1, 1_000_000),
    ("optimize", "tasks"): (0, 1_000),
    ("optimize", "generations"): (1, 10_000),
    ("optimize", "population"): (4, 10_000),
    ("bench", "tasks"): (0, 10_000),
    ("bench", "generations"): (1, 10_000),
    ("bench", "population"): (4, 10_000),
}
STR_KEYS = {
    ("data", "plant"): "lab",
    ("train", "grid"): "quick",
    ("train", "inputs"): "physics",
    ("optimize", "algorithm"): "ga",
    ("optimize", "fitness"): "physics",
    ("synth", "source"): "train",
    ("bench", "configurations"): "thesis",
    ("bench", "fitness"): "physics",
}
LIST_KEYS = {("train", "families"): "par", ("train", "targets"): "E", ("synth", "methods"): "copula"}


def _model_card_edit(**edit: Any) -> dict[str, str | bytes]:
    return {MODEL: "", "m/xgb-E/card.json": ("@card", json.dumps(edit))}  # type: ignore[dict-item]


DATA_OWNER = "data/ (ingest guards, issue 15 item 5)"
LEARN_OWNER = "learn/ (model loading, issue 15 item 2)"
CLI_OPT_OWNER = "cli/_optimize.py (joints.json is read without checks)"

# fmt: off
CASES = [
    # ---- IRML: through `robot show`
    C("irml-valid", "robot show {in}/r.irml", 0, "Six", {"r.irml": IRML}),
    *(
        C(
            f"irml-missing-{tag}",
            "robot show {in}/r.irml",
            2,
            f"missing <{tag}>",
            {"r.irml": re.sub(f"<{tag}>.*?</{tag}>", "", IRML, count=1, flags=re.S)},
        )
        for tag in IRML_TAGS_MISSING
    ),
    *(
        C(f"irml-{tag}-{kind}", "robot show {in}/r.irml", 2, f"<{tag}>", {"r.irml": _irml_first(tag, value)})
        for tag in IRML_NUMBERS
        for kind, value in BAD_NUMBERS.items()
    ),
    C("irml-q-two-variables", "robot show {in}/r.irml", 2, "<q>", {"r.irml": IRML.replace("<q>q1</q>", "<q>q1+q2</q>")}),
    C("irml-q-times-two", "robot show {in}/r.irml", 2, "not ±q1", {"r.irml": IRML.replace("<q>q1</q>", "<q>2*q1</q>")}),
    C("irml-q-power", "robot show {in}/r.irml", 2, "power", {"r.irml": IRML.replace("<q>q1</q>", "<q>q1**2</q>")}),
    C("irml-q-complex-offset", "robot show {in}/r.irml", 2, "complex", {"r.irml": IRML.replace("<q>q1</q>", "<q>q1+(-2)**0.5</q>")}),
    C("irml-type-linear", "robot show {in}/r.irml", 2, "linear (prismatic)", {"r.irml": IRML.replace("<type>R</type>", "<type>L</type>", 1)}),
    C("irml-type-unknown", "robot show {in}/r.irml", 2, "unknown joint type", {"r.irml": IRML.replace("<type>R</type>", "<type>Z</type>", 1)}),
    C("irml-xi-zero", "robot show {in}/r.irml", 2, "xi is 0", {"r.irml": IRML.replace("<xi>1</xi>", "<xi>0</xi>", 1)}),
    C("irml-xi-two", "robot show {in}/r.irml", 2, "not 0 or 1", {"r.irml": IRML.replace("<xi>1</xi>", "<xi>2</xi>", 1)}),
    C("irml-duplicate-id", "robot show {in}/r.irml", 2, "duplicate joint id", {"r.irml": IRML.replace('id="2"', 'id="1"')}),
    C("irml-id-text", "robot show {in}/r.irml", 2, "id is not an integer", {"r.irml": IRML.replace('id="1"', 'id="one"')}),
    C("irml-id-huge", "robot show {in}/r.irml", 2, "id is not an integer", {"r.irml": IRML.replace('id="1"', f'id="{"9" * 5000}"')}),
    C("irml-id-missing", "robot show {in}/r.irml", 2, "has no id", {"r.irml": IRML.replace(' id="1"', "")}),
    C("irml-no-joints", "robot show {in}/r.irml", 2, "has no <joint>", {"r.irml": "<robot><name>X</name></robot>"}),
    C("irml-no-name", "robot show {in}/r.irml", 2, "missing <name>", {"r.irml": IRML.replace("<name>Six</name>", "")}),
    C("irml-two-d", "robot show {in}/r.irml", 2, "appears 2 times", {"r.irml": IRML.replace("<d>0.1</d>", "<d>0.1</d><d>0.2</d>", 1)}),
    C("irml-wrong-root", "robot show {in}/r.irml", 2, "root element", {"r.irml": IRML.replace("robot>", "robt>")}),
    C("irml-namespace-root", "robot show {in}/r.irml", 2, "root element", {"r.irml": "<x:robot xmlns:x='u'><name>X</name></x:robot>"}),
    C("irml-truncated", "robot show {in}/r.irml", 2, "not well-formed", {"r.irml": IRML[:-20]}),
    C("irml-empty", "robot show {in}/r.irml", 2, "not well-formed", {"r.irml": b""}),
    C("irml-binary", "robot show {in}/r.irml", 2, "not well-formed", {"r.irml": bytes(range(256))}),
    C("irml-nul-byte", "robot show {in}/r.irml", 2, "not well-formed", {"r.irml": IRML.replace("<d>0.1</d>", "<d>0.1\x00</d>", 1)}),
    C("irml-utf16-with-bom", "robot show {in}/r.irml", 0, "Six", {"r.irml": IRML.encode("utf-16")}),
    C("irml-latin1-declared-utf8", "robot show {in}/r.irml", 2, "not well-formed", {"r.irml": IRML.replace("Six", "S\xe9x").encode("latin-1")}),
    C("irml-unknown-encoding", "robot show {in}/r.irml", 2, "cannot be decoded", {"r.irml": "<?xml version='1.0' encoding='klingon'?>" + IRML}),
    C("irml-dtd", "robot show {in}/r.irml", 2, "not allowed", {"r.irml": "<!DOCTYPE robot>" + IRML}),
    C("irml-xxe", "robot show {in}/r.irml", 2, "not allowed", {"r.irml": '<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>' + IRML.replace("Six", "&x;")}),
    C("irml-billion-laughs", "robot show {in}/r.irml", 2, "not allowed", {"r.irml": '<!DOCTYPE r [<!ENTITY a "aaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;">]>'+ IRML.replace("Six", "&b;")}),
    C("irml-deep-info", "robot show {in}/r.irml", 2, "nested deeper", {"r.irml": IRML.replace("<reach>", "<a>" * 5000 + "</a>" * 5000 + "<reach>")}),
    C("irml-deep-in-value", "robot show {in}/r.irml", 2, "<d>", {"r.irml": IRML.replace("<d>0.1</d>", "<d>" + "<b>" * 3000 + "</b>" * 3000 + "</d>", 1)}),
    C("irml-65-joints", "robot show {in}/r.irml", 2, "at most 64", {"r.irml": "<robot><name>X</name>" + "".join(_irml_joint(i) for i in range(1, 66)) + "</robot>"}),
    C("irml-oversized", "robot show {in}/r.irml", 2, "larger than 4 MiB", {"r.irml": IRML.replace("<reach>", " " * (5 << 20) + "<reach>")}),
    C("irml-reach-nan", "robot show {in}/r.irml", 2, "<reach>", {"r.irml": IRML.replace("<reach>0.6</reach>", "<reach>nan</reach>")}),
    C("irml-range-set-no-name", "robot show {in}/r.irml", 2, "no name attribute", {"r.irml": IRML.replace("</robot>", "<range-set><joint id='1'><lower>0</lower><upper>1</upper></joint></range-set></robot>")}),
    C("irml-range-set-missing-joint", "robot show {in}/r.irml", 2, "has no range for joint", {"r.irml": IRML.replace("</robot>", "<range-set name='lab'><joint id='1'><lower>0</lower><upper>1</upper></joint></range-set></robot>")}),
    C("irml-range-set-bad-id", "robot show {in}/r.irml", 2, "no integer id", {"r.irml": IRML.replace("</robot>", "<range-set name='lab'><joint id='x'/></range-set></robot>")}),
    C("irml-payload-incomplete", "robot show {in}/r.irml", 2, "<payload>", {"r.irml": IRML.replace("</robot>", "<payload><link-mass>1</link-mass></payload></robot>")}),
    C("irml-is-a-folder", "robot show {in}", 2, "", {}),
    C("irml-unknown-suffix", "robot show {in}/r.txt", 2, "unknown robot file type", {"r.txt": IRML}),
    C("irml-payload-negative-mass-show-strict", "robot show --strict {in}/r.irml", 1, "mass -1.5 kg is not positive", {"r.irml": IRML.replace("</robot>", "<payload><link-mass>-1.5</link-mass><center><x>0</x><y>0</y><z>0</z></center><inertia><xx>0</xx><xy>0</xy><xz>0</xz><yx>0</yx><yy>0</yy><yz>0</yz><zx>0</zx><zy>0</zy><zz>0</zz></inertia></payload></robot>")}),
    C("irml-payload-negative-mass-optimize", OPT + " --fitness physics --robot {in}/r.irml --out {out}", 2, "not positive", {"r.irml": IRML.replace("</robot>", "<payload><link-mass>-1.5</link-mass><center><x>0</x><y>0</y><z>0</z></center><inertia><xx>0</xx><xy>0</xy><xz>0</xz><yx>0</yx><yy>0</yy><yz>0</yz><zx>0</zx><zy>0</zy><zz>0</zz></inertia></payload></robot>")}),
    C("irml-negative-mass-optimize", OPT + " --fitness physics --robot {in}/r.irml --out {out}", 2, "mass", {"r.irml": IRML.replace("<link-mass>1.5</link-mass>", "<link-mass>-1.5</link-mass>", 1)}),
    # ---- URDF: through `robot show`
    C("urdf-valid", "robot show {in}/r.urdf", 0, "six", {"r.urdf": URDF}),
    *(
        C(
            f"urdf-{attr}-{kind}",
            "robot show {in}/r.urdf",
            2,
            "r.urdf",
            {"r.urdf": URDF.replace(old, new.format(value if "xyz" in attr or kind != "short" else "1 2"), 1)},
        )
        for attr, (old, new) in URDF_ATTRS.items()
        for kind, value in BAD_URDF_VALUES.items()
    ),
    C("urdf-empty", "robot show {in}/r.urdf", 2, "not well-formed", {"r.urdf": b""}),
    C("urdf-binary", "robot show {in}/r.urdf", 2, "not well-formed", {"r.urdf": bytes(range(256))}),
    C("urdf-utf16", "robot show {in}/r.urdf", 2, "r.urdf", {"r.urdf": URDF.encode("utf-16")}),
    C("urdf-dtd", "robot show {in}/r.urdf", 2, "not allowed", {"r.urdf": "<!DOCTYPE robot>" + URDF.replace('<?xml version="1.0"?>', "")}),
    C("urdf-xxe", "robot show {in}/r.urdf", 2, "not allowed", {"r.urdf": '<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>'+ URDF.replace('<?xml version="1.0"?>', "").replace('name="six"', 'name="&x;"')}),
    C("urdf-deep", "robot show {in}/r.urdf", 2, "r.urdf", {"r.urdf": URDF.replace('<link name="l0"/>', '<link name="l0"/>' + "<a>" * 5000 + "</a>" * 5000)}),
    C("urdf-wrong-root", "robot show {in}/r.urdf", 2, "root element", {"r.urdf": URDF.replace("<robot ", "<robt ").replace("</robot>", "</robt>")}),
    C("urdf-no-robot-name", "robot show {in}/r.urdf", 2, "no name", {"r.urdf": URDF.replace(' name="six"', "")}),
    C("urdf-no-links", "robot show {in}/r.urdf", 2, "no <link>", {"r.urdf": '<robot name="x"/>'}),
    C("urdf-link-no-name", "robot show {in}/r.urdf", 2, "<link> has no name", {"r.urdf": URDF.replace('<link name="l0"/>', "<link/>")}),
    C("urdf-duplicate-link", "robot show {in}/r.urdf", 2, "appears twice", {"r.urdf": URDF.replace('<link name="l0"/>', '<link name="l0"/><link name="l0"/>')}),
    C("urdf-duplicate-joint", "robot show {in}/r.urdf", 2, "appears twice", {"r.urdf": URDF.replace('name="j2"', 'name="j1"')}),
    C("urdf-joint-no-name", "robot show {in}/r.urdf", 2, "<joint> has no name", {"r.urdf": URDF.replace(' name="j1"', "")}),
    C("urdf-joint-type-bogus", "robot show {in}/r.urdf", 2, "has type 'bogus'", {"r.urdf": URDF.replace('type="revolute"', 'type="bogus"', 1)}),
    C("urdf-joint-no-type", "robot show {in}/r.urdf", 2, "has type ''", {"r.urdf": URDF.replace(' type="revolute"', "", 1)}),
    C("urdf-prismatic", "robot show {in}/r.urdf", 2, "is prismatic", {"r.urdf": URDF.replace('type="revolute"', 'type="prismatic"', 1)}),
    C("urdf-continuous", "robot show {in}/r.urdf", 0, "is continuous", {"r.urdf": URDF.replace('type="revolute"', 'type="continuous"', 1)}),
    C("urdf-floating", "robot show {in}/r.urdf", 2, "is floating", {"r.urdf": URDF.replace('type="revolute"', 'type="floating"', 1)}),
    C("urdf-four-joints", "robot show {in}/r.urdf", 2, "has 4 movable joints", {"r.urdf": URDF.replace('type="revolute"', 'type="fixed"', 2)}),
    C("urdf-missing-child-link", "robot show {in}/r.urdf", 2, "is not a <link>", {"r.urdf": URDF.replace('<child link="l1"/>', '<child link="nope"/>')}),
    C("urdf-no-parent", "robot show {in}/r.urdf", 2, "needs one <parent", {"r.urdf": URDF.replace('<parent link="l0"/>', "")}),
    C("urdf-self-loop", "robot show {in}/r.urdf", 2, "to itself", {"r.urdf": URDF.replace('<child link="l1"/>', '<child link="l0"/>')}),
    C("urdf-two-parents", "robot show {in}/r.urdf", 2, "child of two joints", {"r.urdf": URDF.replace('<child link="l2"/>', '<child link="l1"/>')}),
    C("urdf-cycle", "robot show {in}/r.urdf", 2, "not connected to the root", {"r.urdf": URDF.replace('<parent link="l0"/>', '<parent link="l6"/>')}),
    C("urdf-two-roots", "robot show {in}/r.urdf", 2, "2 root links", {"r.urdf": URDF.replace('<link name="l0"/>', '<link name="l0"/><link name="stray"/>')}),
    C("urdf-no-limit", "robot show {in}/r.urdf", 2, "has no <limit", {"r.urdf": URDF.replace('<limit lower="-3" upper="3" velocity="4" effort="50"/>', "", 1)}),
    C("urdf-limit-no-effort", "robot show {in}/r.urdf", 2, "effort", {"r.urdf": URDF.replace(' effort="50"', "", 1)}),
    C("urdf-inertial-no-mass", "robot show {in}/r.urdf", 2, "mass", {"r.urdf": URDF.replace('<mass value="1.5"/>', "", 1)}),
    C("urdf-inertia-missing-izz", "robot show {in}/r.urdf", 2, "missing izz", {"r.urdf": URDF.replace(' izz="0.01"', "", 1)}),
    C("urdf-inertial-no-inertia", "robot show {in}/r.urdf", 2, "inertia", {"r.urdf": re.sub("<inertia [^>]*/>", "", URDF, count=1)}),
    C("urdf-visual-bad-box", "robot show {in}/r.urdf", 2, "refused part of it", {"r.urdf": URDF.replace('<link name="l0"/>', '<link name="l0"><visual><geometry><box size="a b c"/></geometry></visual></link>')}),
    C("urdf-visual-mesh-no-file", "robot show {in}/r.urdf", 2, "filename", {"r.urdf": URDF.replace('<link name="l0"/>', '<link name="l0"><visual><geometry><mesh/></geometry></visual></link>')}),
    C("urdf-dynamics-bad", "robot show {in}/r.urdf", 2, "damping", {"r.urdf": URDF.replace("<axis", '<dynamics damping="x"/><axis', 1)}),
    C("urdf-missing-tool-frame", "robot fk {in}/r.urdf --q 0,0,0,0,0,0", 0, "position mm", {"r.urdf": URDF.replace('<link name="tool0"/><joint name="t" type="fixed"><parent link="l6"/><child link="tool0"/></joint>', "")}),
    C("urdf-negative-mass-optimize", OPT + " --fitness physics --robot {in}/r.urdf --out {out}", 2, "mass", {"r.urdf": URDF.replace('<mass value="1.5"/>', '<mass value="-1.5"/>', 1)}),
    C("urdf-zero-axis-show-strict", "robot show --strict {in}/r.urdf", 1, "axis", {"r.urdf": URDF.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>', 1)}),
    # ---- experiment TOML: through `run` (every case is refused before anything runs)
    *(
        C(
            f"toml-{section or 'top'}-{key}-{kind}",
            "run {in}/s.toml --out {out}",
            2,
            needle,
            {"s.toml": _toml_set(section, key, value)},
        )
        for (section, key), (low, high) in INT_KEYS.items()
        for kind, value, needle in (
            ("below", str(low - 1), f"{key} must be ≥ {low}"),
            ("above", str(high + 1), f"{key} must be ≤"),
            ("huge", "1_000_000_000_000", f"{low}..{high:_}"),
            ("float", "1e12", f"{key} must be an integer"),
            ("nan", "nan", f"{key} must be an integer"),
            ("string", '"7"', f"{key} must be an integer"),
            ("bool", "true", f"{key} must be an integer"),
        )
    ),
    *(
        C(
            f"toml-{section}-{key}-{kind}",
            "run {in}/s.toml --out {out}",
            2,
            needle,
            {"s.toml": _toml_set(section, key, value)},
        )
        for (section, key), good in STR_KEYS.items()
        for kind, value, needle in (
            ("unknown", '"nonsense"', "is not allowed"),
            ("integer", "3", "must be a string"),
            ("list", f'["{good}"]', "must be a string"),
        )
    ),
    *(
        C(
            f"toml-{section}-{key}-{kind}",
            "run {in}/s.toml --out {out}",
            2,
            needle,
            {"s.toml": _toml_set(section, key, value)},
        )
        for (section, key), good in LIST_KEYS.items()
        for kind, value, needle in (
            ("string", f'"{good}"', "list of strings"),
            ("bad-item", '["knn"]', "'knn'"),
            ("duplicate", f'["{good}", "{good}"]', "more than once"),
            ("numbers", "[1, 2]", "list of strings"),
        )
    ),
    C("toml-name-dotdot", "run {in}/s.toml --out {out}", 2, "must be a folder name", {"s.toml": TOML.replace('"corpus"', '".."')}),
    C("toml-name-slash", "run {in}/s.toml --out {out}", 2, "must be a folder name", {"s.toml": TOML.replace('"corpus"', '"a/b"')}),
    C("toml-name-nul", "run {in}/s.toml --out {out}", 2, "control characters", {"s.toml": TOML.replace('"corpus"', '"a\\u0000b"')}),
    C("toml-name-long", "run {in}/s.toml --out {out}", 2, "1 to 100 characters", {"s.toml": TOML.replace('"corpus"', '"' + "x" * 500 + '"')}),
    C("toml-name-integer", "run {in}/s.toml --out {out}", 2, "name must be a string", {"s.toml": TOML.replace('"corpus"', "7")}),
    C("toml-name-missing", "run {in}/s.toml --out {out}", 2, "missing key 'name'", {"s.toml": TOML.replace('name = "corpus"\n', "")}),
    C("toml-robot-unknown", "run {in}/s.toml --out {out}", 2, "irb999", {"s.toml": _toml_set("", "robot", '"irb999"')}),
    C("toml-robot-nul", "run {in}/s.toml --out {out}", 2, "control characters", {"s.toml": _toml_set("", "robot", '"irb\\u0000"')}),
    C("toml-scheduler-newline", "run {in}/s.toml --out {out}", 2, "control characters", {"s.toml": _toml_set("", "scheduler", '"tcp://a\\nb"')}),
    C("toml-range-set-unknown", "run {in}/s.toml --out {out}", 2, "range_set = 'moon'", {"s.toml": _toml_set("optimize", "range_set", '"moon"')}),
    C("toml-unknown-key", "run {in}/s.toml --out {out}", 2, "unknown key 'folds'", {"s.toml": _toml_set("train", "folds", "2")}),
    C("toml-unknown-top-key", "run {in}/s.toml --out {out}", 2, "unknown key 'colour'", {"s.toml": _toml_set("", "colour", '"red"')}),
    C("toml-unknown-section", "run {in}/s.toml --out {out}", 2, "unknown section [trian]", {"s.toml": TOML.replace("[train]", "[trian]")}),
    C("toml-array-of-tables", "run {in}/s.toml --out {out}", 2, "unknown key 'data'", {"s.toml": TOML.replace("[data]", "[[data]]")}),
    C("toml-subtable", "run {in}/s.toml --out {out}", 2, "unknown key 'x'", {"s.toml": TOML + "[train.x]\ny = 1\n"}),
    C("toml-broken", "run {in}/s.toml --out {out}", 2, "not valid TOML", {"s.toml": TOML.replace("[data]", "[data")}),
    C("toml-duplicate-key", "run {in}/s.toml --out {out}", 2, "not valid TOML", {"s.toml": TOML.replace("seed = 1", "seed = 1\nseed = 2")}),
    C("toml-deep-arrays", "run {in}/s.toml --out {out}", 2, "not valid TOML", {"s.toml": TOML + "[bench]\nx = " + "[" * 5000 + "]" * 5000 + "\n"}),
    C("toml-deep-inline-tables", "run {in}/s.toml --out {out}", 2, "not valid TOML", {"s.toml": "x = " + "{a=" * 3000 + "1" + "}" * 3000 + "\n" + TOML}),
    C("toml-binary", "run {in}/s.toml --out {out}", 2, "not UTF-8", {"s.toml": bytes(range(128, 256))}),
    C("toml-nul-byte", "run {in}/s.toml --out {out}", 2, "not valid TOML", {"s.toml": TOML.replace("seed = 1", "seed = 1\x00")}),
    C("toml-empty", "run {in}/s.toml --out {out}", 2, "missing key 'name'", {"s.toml": b""}),
    C("toml-oversized", "run {in}/s.toml --out {out}", 2, "larger than 1 MiB", {"s.toml": TOML + "#" * (2 << 20) + "\n"}),
    C("toml-is-a-folder", "run {in} --out {out}", 2, "is a folder", {}),
    C("toml-missing-file", "run {in}/nope.toml --out {out}", 2, "no such experiment file", {}),
    C("toml-train-logs-without-test-logs", "run {in}/s.toml --out {out}", 2, "give both train_logs and test_logs", {"s.toml": _toml_set("data", "train_logs", '["a.csv"]'), "a.csv": LOG}),
    C("toml-train-logs-missing-file", "run {in}/s.toml --out {out}", 2, "does not exist", {"s.toml": _toml_set("data", "train_logs", '["nope.csv"]').replace("[data]\n", '[data]\ntest_logs = ["nope.csv"]\n')}),
    C("toml-synth-micro-without-micro-moves", "run {in}/s.toml --out {out}", 2, "micro_moves ≥ 1", {"s.toml": _toml_set("synth", "methods", '["copula"]')}),
    C("toml-synth-rows-below-20", "run {in}/s.toml --out {out}", 2, "rows must be ≥ 20", {"s.toml": _toml_set("synth", "methods", '["copula"]').replace("[synth]\n", "[synth]\nrows = 5\nsource = 'train'\n")}),
    C("toml-surrogate-joints-without-targets", "run {in}/s.toml --out {out}", 2, "fitness = 'surrogate-joints' needs", {"s.toml": _toml_set("optimize", "fitness", '"surrogate-joints"')}),
    C("toml-value-long-cut-short", "run {in}/s.toml --out {out}", 2, "...", {"s.toml": _toml_set("train", "grid", '"' + "g" * 5000 + '"')}),
    # ---- joint logs: through `ingest`
    C("log-valid", "ingest {in}/a.csv --out {out}/t.parquet", 0, "wrote", {"a.csv": LOG}),
    *(
        C(
            f"log-{col}-{kind}",
            "ingest {in}/a.csv --out {out}/t.parquet",
            2,
            f"field {col}",
            {"a.csv": _log_cell(5, col, value)},
        )
        for col in ("t", "q1", "dq3", "tau6")
        for kind, value in (
            ("text", "abc"),
            ("nan", "nan"),
            ("inf", "inf"),
            ("empty", ""),
            ("overflow", "1e999"),
            ("hex", "0x1f"),
        )
    ),
    *(
        C(
            f"log-lacks-{col}",
            "ingest {in}/a.csv --out {out}/t.parquet",
            2,
            f"lacks column(s) {col}",
            {
                "a.csv": "\n".join(
                    ",".join(c for i, c in enumerate(line.split(",")) if i != HEADER.index(col))
                    for line in LOG_LINES
                )
                + "\n"
            },
        )
        for col in ("q1", "dq3", "tau6", "q6")
    ),
    C("log-lacks-t", "ingest {in}/a.csv --out {out}/t.parquet", 2, "a.csv", {"a.csv": "\n".join(line.split(",", 1)[1] for line in LOG_LINES) + "\n"}),
    C("log-duplicated-column", "ingest {in}/a.csv --out {out}/t.parquet", 2, "duplicated column(s) q1", {"a.csv": "\n".join([LOG_LINES[0] + ",q1"] + [r + ",0.1" for r in LOG_LINES[1:]]) + "\n"}),
    C("log-empty", "ingest {in}/a.csv --out {out}/t.parquet", 2, "is empty", {"a.csv": b""}),
    C("log-header-only", "ingest {in}/a.csv --out {out}/t.parquet", 2, "no data lines", {"a.csv": LOG_LINES[0] + "\n"}),
    C("log-one-row", "ingest {in}/a.csv --out {out}/t.parquet", 2, "a.csv", {"a.csv": "\n".join(LOG_LINES[:2]) + "\n"}),
    C("log-two-rows", "ingest {in}/a.csv --out {out}/t.parquet", 2, "a.csv", {"a.csv": "\n".join(LOG_LINES[:3]) + "\n"}),
    C("log-not-utf8", "ingest {in}/a.csv --out {out}/t.parquet", 2, "not UTF-8", {"a.csv": b"\xff\xfe" + LOG.encode()}),
    C("log-binary", "ingest {in}/a.csv --out {out}/t.parquet", 2, "a.csv", {"a.csv": bytes(range(256)) * 4}),
    C("log-nul-in-line", "ingest {in}/a.csv --out {out}/t.parquet", 2, "a.csv", {"a.csv": _log_cell(3, "q2", "0.1\x00")}),
    C("log-semicolons", "ingest {in}/a.csv --out {out}/t.parquet", 2, "a.csv", {"a.csv": LOG.replace(",", ";")}),
    C("log-short-row", "ingest {in}/a.csv --out {out}/t.parquet", 2, "line 4", {"a.csv": "\n".join(LOG_LINES[:3] + [LOG_LINES[3].rsplit(",", 1)[0]] + LOG_LINES[4:]) + "\n"}),
    C("log-long-row", "ingest {in}/a.csv --out {out}/t.parquet", 2, "line 4", {"a.csv": "\n".join(LOG_LINES[:3] + [LOG_LINES[3] + ",1"] + LOG_LINES[4:]) + "\n"}),
    C("log-time-backwards", "ingest {in}/a.csv --out {out}/t.parquet", 2, "does not increase", {"a.csv": _log_cell(10, "t", "0.0")}),
    C("log-duplicated-row", "ingest {in}/a.csv --out {out}/t.parquet", 2, "duplicates line", {"a.csv": "\n".join(LOG_LINES[:5] + [LOG_LINES[4]] + LOG_LINES[5:]) + "\n"}),
    C("log-lone-cr", "ingest {in}/a.csv --out {out}/t.parquet", 2, "a.csv", {"a.csv": LOG.replace("\n0.000000,", "\n0\r.000000,", 1)}),
    C("log-hour-gap", "ingest {in}/a.csv --out {out}/t.parquet", 0, "gap", {"a.csv": "\n".join(LOG_LINES[:31]+ [",".join([f"{3600 + float(r.split(',')[0]):.6f}"] + r.split(",")[1:])for r in LOG_LINES[31:]])+ "\n"}),  # split there, not refused (design)
    C("log-milliseconds", "ingest {in}/a.csv --out {out}/t.parquet", 2, "a.csv", {"a.csv": "\n".join([LOG_LINES[0]]+ [",".join([f"{1000 * float(r.split(',')[0]):.3f}"] + r.split(",")[1:])for r in LOG_LINES[1:]])+ "\n"}),
    C("log-degrees", "ingest {in}/a.csv --out {out}/t.parquet --robot irb120", 2, "a.csv", {"a.csv": _log(scale=0.3 * 57.29578)}),
    C("log-seven-joints", "ingest {in}/a.csv --out {out}/t.parquet", 0, "21 inputs", {"a.csv": _log(joints=7)}),
    C("log-eight-joints", "ingest {in}/a.csv --out {out}/t.parquet", 2, "5 to 7 joints", {"a.csv": _log(joints=8)}),
    C("log-four-joints", "ingest {in}/a.csv --out {out}/t.parquet", 2, "a.csv", {"a.csv": _log(joints=4)}),
    C("log-motionless", "ingest {in}/a.csv --out {out}/t.parquet", 2, "a.csv", {"a.csv": _log(scale=0.0)}),
    C("log-controller-header-short", "ingest {in}/a.csv --out {out}/t.parquet", 2, "a.csv", {"a.csv": "t,q1,dq1,tau1,q2,dq2,tau2,q3,dq3,tau3,q4,dq4,tau4,q5,dq5,tau5,q6,dq6,tau6,x,y,z\n0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n"}),
    C("log-is-a-folder", "ingest {in} --out {out}/t.parquet", 2, "", {}),
    C("log-missing", "ingest {in}/nope.csv --out {out}/t.parquet", 2, "cannot be read", {}),
    C("log-out-is-input", "ingest {in}/a.csv --out {in}/a.csv", 2, "a.csv", {"a.csv": LOG}),
    C("log-out-is-folder", "ingest {in}/a.csv --out {in}", 2, "is a folder", {"a.csv": LOG}),
    C("log-out-under-a-file", "ingest {in}/a.csv --out {in}/a.csv/t.parquet", 2, "is a file, not a folder", {"a.csv": LOG}),
    # ---- model folders and cards: through `optimize --model`
    C("model-valid", OPT + " --fitness surrogate --model {in}/m --out {out}", 0, "", {MODEL: ""}),
    C("model-folder-missing", OPT + " --fitness surrogate --model {in}/nope --out {out}", 2, "no such folder", {}),
    C("model-folder-empty", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "m", {"m/.keep": ""}),
    C("model-one-model-folder", OPT + " --fitness surrogate --model {in}/m/xgb-E --out {out}", 2, "folder of one model", {MODEL: ""}),
    C("model-card-not-json", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "not valid JSON", {MODEL: "", "m/xgb-E/card.json": "{not json"}),
    C("model-card-binary", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "card.json", {MODEL: "", "m/xgb-E/card.json": bytes(range(256))}),
    C("model-card-list", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "not an object", {MODEL: "", "m/xgb-E/card.json": "[1, 2]"}),
    C("model-card-deep", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "card.json", {MODEL: "", "m/xgb-E/card.json": "[" * 100_000 + "]" * 100_000}),
    C("model-card-empty", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "card.json", {MODEL: "", "m/xgb-E/card.json": ""}),
    *(
        C(
            f"model-card-lacks-{key}",
            OPT + " --fitness surrogate --model {in}/m --out {out}",
            2,
            repr(key),
            {MODEL: "", "m/xgb-E/card.json": ("@drop", key)},
        )  # type: ignore[dict-item]
        for key in ("family", "target", "input_columns", "feature_set", "inputs", "file", "cv_grouped")
    ),
    C("model-card-family-unknown", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "card.json", _model_card_edit(family="knn")),
    C("model-card-target-unknown", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "card.json", _model_card_edit(target="E9")),
    C("model-card-feature-set-unknown", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "card.json", _model_card_edit(feature_set="full41")),
    C("model-card-inputs-unknown", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "card.json", _model_card_edit(inputs="magic")),
    C("model-card-columns-shuffled", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "card.json", {MODEL: "", "m/xgb-E/card.json": ("@shuffle", "")}),  # type: ignore[dict-item]C("model-card-columns-fewer", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "card.json", {MODEL: "", "m/xgb-E/card.json": ("@fewer", "")}),  # type: ignore[dict-item]C("model-card-columns-not-list", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "card.json", _model_card_edit(input_columns="x")),
    C("model-card-file-escapes", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "m", _model_card_edit(file="../../../etc/passwd.json")),
    C("model-card-file-absolute", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "m", _model_card_edit(file="/etc/hostname.json")),
    C("model-card-file-missing", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "m", _model_card_edit(file="gone.json")),
    C("model-card-file-number", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "m", _model_card_edit(file=7)),
    C("model-card-other-robot", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "'IRB 140'", _model_card_edit(robot="IRB 140")),
    C("model-card-cv-grouped-string", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "card.json", _model_card_edit(cv_grouped="good")),
    C("model-json-garbage", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "model.json", {MODEL: "", "m/xgb-E/model.json": "{not json"}),
    C("model-json-empty-object", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "model.json", {MODEL: "", "m/xgb-E/model.json": "{}"}),
    C("model-json-binary", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "model.json", {MODEL: "", "m/xgb-E/model.json": bytes(range(256))}),
    C("model-skops-garbage", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "m", {MODEL: "", "m/xgb-E/card.json": ("@card", json.dumps({"family": "par", "file": "model.skops"})), "m/xgb-E/model.skops": b"PK\x03\x04garbage"}),  # type: ignore[dict-item]
    # ---- joints.json next to the models
    C("joints-json-valid", OPT + " --fitness surrogate --model {in}/m --out {out}", 0, "", {MODEL: "", "m/joints.json": '{"joints_by_influence": [2, 1, 3, 4, 5, 6]}'}),
    C("joints-json-not-json", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "joints.json", {MODEL: "", "m/joints.json": "{oops"}),
    C("joints-json-list", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "joints.json", {MODEL: "", "m/joints.json": "[1, 2]"}),
    C("joints-json-no-key", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "joints.json", {MODEL: "", "m/joints.json": "{}"}),
    C("joints-json-strings", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "joints.json", {MODEL: "", "m/joints.json": '{"joints_by_influence": ["a"]}'}),
    C("joints-json-out-of-range", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "joints.json", {MODEL: "", "m/joints.json": '{"joints_by_influence": [99, -5]}'}),
    C("joints-json-binary", OPT + " --fitness surrogate --model {in}/m --out {out}", 2, "joints.json", {MODEL: "", "m/joints.json": b"\xff\xfe\x00"}),
    # ---- CLI arguments
    C("cli-no-args", "", 2, "no command given", {}),
    C("cli-unknown-command", "frobnicate", 2, "frobnicate", {}),
    C("cli-unknown-option", "robot show irb120 --colour red", 2, "--colour", {}),
    C("cli-version", "--version", 0, "joulepath", {}),
    C("cli-robot-unknown", "robot show irb999", 2, "irb999", {}),
    C("cli-robot-nul", "robot show irb\x00120", 2, "irb", {}),
    C("cli-fk-too-few", "robot fk irb120 --q 0,0", 2, "expected 6 joint values", {}),
    C("cli-fk-text", "robot fk irb120 --q a,b,c,d,e,f", 2, "--q", {}),
    C("cli-fk-nan", "robot fk irb120 --q nan,0,0,0,0,0", 2, "--q", {}),
    C("cli-fk-inf", "robot fk irb120 --q inf,0,0,0,0,0", 2, "--q", {}),
    C("cli-simulate-zero-moves", "simulate --moves 0 --out {out}/a.csv", 2, "--moves", {}),
    C("cli-simulate-negative-seed", "simulate --moves 1 --seed -1 --out {out}/a.csv", 2, "--seed", {}),
    C("cli-simulate-seed-2-32", "simulate --moves 1 --seed 4294967296 --out {out}/a.csv", 2, "--seed", {}),
    C("cli-simulate-moves-text", "simulate --moves many --out {out}/a.csv", 2, "--moves", {}),
    C("cli-simulate-unknown-plant", "simulate --moves 1 --plant moon --out {out}/a.csv", 2, "moon", {}),
    C("cli-simulate-unknown-plan", "simulate --plan other --out {out}", 2, "--plan", {}),
    C("cli-simulate-zero-workers", "simulate --plan thesis --workers 0 --out {out}", 2, "--workers", {}),
    C("cli-rapid-zero-moves", "rapid collect --moves 0 --out {out}", 2, "--moves", {}),
    C("cli-rapid-unknown-mode", "rapid collect --moves 2 --mode other --out {out}", 2, "other", {}),
    C("cli-rapid-unknown-range-set", "rapid collect --moves 2 --range-set moon --out {out}", 2, "moon", {}),
    C("cli-optimize-duration-nan", "optimize --start 0,0,0,0,0,0 --end 0.5,0,0,0,0,0 --duration nan --fitness physics --out {out}", 2, "duration", {}),
    C("cli-optimize-duration-inf", "optimize --start 0,0,0,0,0,0 --end 0.5,0,0,0,0,0 --duration inf --fitness physics --out {out}", 2, "duration", {}),
    C("cli-optimize-duration-zero", "optimize --start 0,0,0,0,0,0 --end 0.5,0,0,0,0,0 --duration 0 --fitness physics --out {out}", 2, "duration", {}),
    C("cli-optimize-duration-huge", "optimize --start 0,0,0,0,0,0 --end 0.5,0,0,0,0,0 --duration 1e9 --fitness physics --out {out}", 2, "longer than 60 s", {}),
    C("cli-optimize-start-nan", "optimize --start nan,0,0,0,0,0 --end 0.5,0,0,0,0,0 --duration 1 --fitness physics --out {out}", 2, "start", {}),
    C("cli-optimize-start-inf", "optimize --start inf,0,0,0,0,0 --end 0.5,0,0,0,0,0 --duration 1 --fitness physics --out {out}", 2, "start", {}),
    C("cli-optimize-start-seven", "optimize --start 0,0,0,0,0,0,0 --end 0.5,0,0,0,0,0 --duration 1 --fitness physics --out {out}", 2, "expected 6 joint values", {}),
    C("cli-optimize-start-empty", "optimize --start , --end 0.5,0,0,0,0,0 --duration 1 --fitness physics --out {out}", 2, "expected 6 joint values", {}),
    C("cli-optimize-start-outside", "optimize --start 0,2.5,0,0,0,0 --end 0,0,0,0,0,0 --duration 1 --fitness physics --out {out}", 2, "outside its range", {}),
    C("cli-optimize-start-equals-end", "optimize --start 0,0,0,0,0,0 --end 0,0,0,0,0,0 --duration 1 --fitness physics --generations 1 --population 4 --out {out}", 2, "", {}),
    C("cli-optimize-population-3", "optimize --start 0,0,0,0,0,0 --end 0.5,0,0,0,0,0 --duration 1 --population 3 --out {out}", 2, "--population", {}),
    C("cli-optimize-generations-0", "optimize --start 0,0,0,0,0,0 --end 0.5,0,0,0,0,0 --duration 1 --generations 0 --out {out}", 2, "--generations", {}),
    C("cli-optimize-unknown-algo", "optimize --start 0,0,0,0,0,0 --end 0.5,0,0,0,0,0 --duration 1 --fitness physics --algo pso --out {out}", 2, "pso", {}),
    C("cli-optimize-unknown-fitness", "optimize --start 0,0,0,0,0,0 --end 0.5,0,0,0,0,0 --duration 1 --fitness magic --out {out}", 2, "magic", {}),
    C("cli-optimize-unknown-parametrization", "optimize --start 0,0,0,0,0,0 --end 0.5,0,0,0,0,0 --duration 1 --fitness physics --parametrization spline --out {out}", 2, "spline", {}),
    C("cli-optimize-surrogate-without-model", "optimize --start 0,0,0,0,0,0 --end 0.5,0,0,0,0,0 --duration 1 --fitness surrogate --out {out}", 2, "--model", {}),
    C("cli-optimize-out-is-a-file", OPT + " --fitness physics --out {in}/f.txt", 2, "is a file", {"f.txt": "x"}),
    C("cli-optimize-seed-negative", OPT + " --fitness physics --seed -1 --out {out}", 2, "--seed", {}),
    C("cli-train-cv-1", "train --data {in}/a.parquet --test {in}/a.parquet --cv 1 --out {out}", 2, "--cv", {}),
    C("cli-train-missing-data", "train --data {in}/a.parquet --test {in}/b.parquet --out {out}", 2, "no such file", {}),
    C("cli-train-log-as-table", "train --data {in}/a.csv --test {in}/a.csv --out {out}", 2, "not a readable Parquet", {"a.csv": LOG}),
    C("cli-train-garbage-parquet", "train --data {in}/a.parquet --test {in}/a.parquet --out {out}", 2, "a.parquet", {"a.parquet": b"PAR1garbagePAR1"}),
    C("cli-train-unknown-family", "train --data {in}/a.parquet --test {in}/a.parquet --family knn --out {out}", 2, "knn", {"a.parquet": b"PAR1"}),
    C("cli-train-unknown-target", "train --data {in}/a.parquet --test {in}/a.parquet --target E9 --out {out}", 2, "E9", {"a.parquet": b"PAR1"}),
    C("cli-train-unknown-grid", "train --data {in}/a.parquet --test {in}/a.parquet --grid huge --out {out}", 2, "huge", {"a.parquet": b"PAR1"}),
    C("cli-train-zero-jobs", "train --data {in}/a.parquet --test {in}/a.parquet --jobs 0 --out {out}", 2, "--jobs", {}),
    C("cli-importance-missing", "importance --data {in}/a.parquet --out {out}", 2, "no such file", {}),
    C("cli-importance-unknown-target-and-stub-table", "importance --data {in}/a.parquet --target E9 --out {out}", 2, "a.parquet", {"a.parquet": b"PAR1"}),
    C("cli-importance-garbage", "importance --data {in}/a.parquet --out {out}", 2, "a.parquet", {"a.parquet": bytes(range(256))}),
    C("cli-synth-unknown-method", "synth --method magic --from {in}/a.parquet --rows 10 --out {out}/s.parquet", 2, "magic", {"a.parquet": b"PAR1"}),
    C("cli-synth-zero-rows", "synth --method copula --from {in}/a.parquet --rows 0 --out {out}/s.parquet", 2, "--rows", {}),
    C("cli-synth-missing-model", "synth --model {in}/m.pkl --out {out}/s.parquet", 2, "m.pkl", {}),
    C("cli-synth-garbage-model", "synth --model {in}/m.pkl --out {out}/s.parquet", 2, "m.pkl", {"m.pkl": b"\x80\x04garbage"}),
    C("cli-compare-missing", "compare {in}/a.parquet {in}/b.parquet", 2, "a.parquet", {}),
    C("cli-bench-zero-tasks", "bench-optimizers --tasks 0 --out {out}", 2, "--tasks", {}),
    C("cli-bench-population-2", "bench-optimizers --tasks 1 --population 2 --out {out}", 2, "--population", {}),
    C("cli-run-unknown-bundled", "run nosuch --out {out}", 2, "no such experiment file", {}),
    C("cli-simulate-program-missing", "simulate --program {in}/none.mod --out {out}/a.csv", 2, "no such file or folder", {}),
    C("cli-simulate-program-not-csv", "simulate --program {in}/p.mod --out {out}/a.log", 2, "give a .csv file", {"p.mod": LOOP_MOD}),
    C("cli-simulate-program-var-bound", "simulate --program {in}/p.mod --out {out}/a.csv", 0, "2 moves", {"p.mod": LOOP_MOD.replace("TO 2", "TO n")}),  # a VAR bound: run as the controller runs it
    C("cli-simulate-program-index-past-end", "simulate --program {in}/p.mod --out {out}/a.csv", 2, "p.mod:7: index 3 outside 1..2", {"p.mod": LOOP_MOD.replace("TO 2", "TO 3")}),
    C("cli-simulate-program-step-0", "simulate --program {in}/p.mod --out {out}/a.csv", 2, "STEP 0 never ends", {"p.mod": LOOP_MOD.replace("TO 2", "TO 2 STEP 0")}),
    C("cli-simulate-program-huge-loop", "simulate --program {in}/p.mod --out {out}/a.csv", 2, "p.mod:7: index 3 outside 1..2", {"p.mod": LOOP_MOD.replace("TO 2", "TO 1000000000")}),
    C("cli-simulate-program-with-moves", "simulate --program {in}/p.mod --moves 3 --out {out}/a.csv", 2, "drop --moves", {"p.mod": LOOP_MOD}),
    C("cli-simulate-program-start-nan", "simulate --program {in}/p.mod --start nan,0,0,0,0,0 --out {out}/a.csv", 2, "not a finite number", {"p.mod": LOOP_MOD}),
    C("cli-simulate-start-without-program", "simulate --start 0,0,0,0,0,0 --out {out}/a.csv", 2, "give --program", {}),
    C("cli-measure-no-plan-folder", "measure {in}/a.csv --plan {in}/none --out {out}", 2, "not a folder", {"a.csv": "t\n"}),
    C("cli-measure-plan-without-result", "measure {in}/a.csv --plan {in} --out {out}", 2, "missing result.json", {"a.csv": "t\n"}),
    C("cli-measure-result-not-json", "measure {in}/a.csv --plan {in} --out {out}", 2, "not readable JSON", {"a.csv": "t\n", "result.json": "{", "path.csv": "t\n", "default_path.csv": "t\n"}),
    C("cli-measure-result-without-ends", "measure {in}/a.csv --plan {in} --out {out}", 2, "start_rad must be a list", {"a.csv": "t\n", "result.json": "{}", "path.csv": "t\n", "default_path.csv": "t\n"}),
]
# fmt: on


# --------------------------------------------------------------------------- the model folder


@pytest.fixture(scope="module")
def model_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One small XGBoost model for E on the thesis inputs, saved the way `joulepath train` saves it."""
    from sklearn.pipeline import Pipeline
    from xgboost import XGBRegressor

    from joulepath.learn import EnergyModel, input_columns

    cols = input_columns("full40", "thesis", 6)
    rng = np.random.default_rng(0)
    X = rng.normal(size=(64, len(cols)))
    y = 1.0 + np.abs(X[:, 0])
    model = XGBRegressor(n_estimators=3, max_depth=2, n_jobs=1, random_state=0).fit(X, y)
    card = {
        "family": "xgb",
        "target": "E",
        "feature_set": "full40",
        "inputs": "thesis",
        "input_columns": list(cols),
        "robot": "IRB 120",
        "robot_source": "irb120",
        "cv_grouped": {"r2_mean": 0.5, "r2_std": 0.1, "mae_mean": 0.3, "mae_std": 0.05, "folds": 2},
    }
    folder = tmp_path_factory.mktemp("models") / "m"
    EnergyModel(Pipeline([("model", model)]), card).save(folder / "xgb-E")
    return folder


def _write_inputs(files: dict[str, Any], inp: Path, model_folder: Path) -> None:
    if MODEL in files:
        shutil.copytree(model_folder, inp / "m")
    for name, data in files.items():
        if name == MODEL:
            continue
        path = inp / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(data, tuple):  # an edit of the copied card
            card = json.loads(path.read_text())
            kind, arg = data
            if kind == "@card":
                card |= json.loads(arg)
            elif kind == "@drop":
                card.pop(arg)
            elif kind == "@shuffle":
                card["input_columns"] = card["input_columns"][::-1]
            elif kind == "@fewer":
                card["input_columns"] = card["input_columns"][:-1]
            data = json.dumps(card)
        path.write_bytes(data if isinstance(data, bytes) else data.encode("utf-8", "surrogateescape"))


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def _argv(template: str, inp: Path, out: Path) -> list[str]:
    return [part.replace("{in}", str(inp)).replace("{out}", str(out)) for part in shlex.split(template)]


def test_corpus_has_at_least_300_distinct_cases():
    ids = [c.id for c in CASES]
    assert len(ids) == len(set(ids)) and len(ids) >= 300, len(ids)
    inputs = [(c.values[0], repr(sorted(c.values[3].items()))) for c in CASES]
    assert len(set(inputs)) == len(inputs), "two cases with the same input"


@pytest.mark.parametrize(("template", "rc", "needle", "files"), CASES)
def test_hostile_input(template, rc, needle, files, tmp_path, capsys, model_folder, monkeypatch):
    inp, out = tmp_path / "in", tmp_path / "out"
    inp.mkdir()
    _write_inputs(files, inp, model_folder)
    before = _snapshot(inp)
    monkeypatch.chdir(tmp_path)  # anything written to a default path shows up in tmp_path
    code = main(_argv(template, inp, out))
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err
    assert code == rc, (code, captured.err[-2000:])
    if rc == 2:
        lines = captured.err.splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: "), captured.err[-2000:]
        assert needle in lines[0], lines[0]
        assert not out.exists(), sorted(str(p) for p in out.rglob("*"))
        assert _snapshot(inp) == before, "an input was changed"
        assert sorted(p.name for p in tmp_path.iterdir()) == ["in"]
    else:
        assert needle in captured.out


# --------------------------------------------------------------------------- real processes

SAMPLE = [
    ("robot show {in}/r.irml", {"r.irml": IRML.replace("<d>0.1</d>", "<d>(-1)**0.5</d>", 1)}),
    ("robot show {in}/r.urdf", {"r.urdf": URDF.replace('<mass value="1.5"/>', '<mass value="abc"/>', 1)}),
    ("run {in}/s.toml --out {out}", {"s.toml": _toml_set("data", "train_moves", "1_000_000_000_000")}),
    ("ingest {in}/a.csv --out {out}/t.parquet", {"a.csv": bytes(range(256))}),
    (
        OPT + " --fitness surrogate --model {in}/m --out {out}",
        {MODEL: "", "m/xgb-E/model.json": ("@xgb", "split_indices")},
    ),
    (
        OPT + " --fitness surrogate --model {in}/m --out {out}",
        {MODEL: "", "m/xgb-E/model.json": ("@xgb", "left_children")},
    ),
    (
        OPT + " --fitness surrogate --model {in}/m --out {out}",
        {MODEL: "", "m/xgb-E/model.json": ("@xgb", "cycle")},
    ),
]


def _tamper_xgb(path: Path, how: str) -> None:
    """Tamper with the first tree of an XGBoost JSON model (issue 15: this crashed with a segfault)."""
    doc = json.loads(path.read_text())
    tree = doc["learner"]["gradient_booster"]["model"]["trees"][0]
    if how == "split_indices":
        tree["split_indices"] = [10_000_000 for _ in tree["split_indices"]]
    elif how == "left_children":
        tree["left_children"] = [10_000_000 if c != -1 else -1 for c in tree["left_children"]]
    else:  # a child that points back at the root
        tree["left_children"] = [0 if c != -1 else -1 for c in tree["left_children"]]
    path.write_text(json.dumps(doc))


def _run_process(
    template: str, files: dict[str, Any], folder: Path, model_folder: Path
) -> subprocess.CompletedProcess[str]:
    inp, out = folder / "in", folder / "out"
    inp.mkdir(parents=True)
    plain = {k: v for k, v in files.items() if not (isinstance(v, tuple) and v[0] == "@xgb")}
    _write_inputs(plain, inp, model_folder)
    for name, value in files.items():
        if isinstance(value, tuple) and value[0] == "@xgb":
            _tamper_xgb(inp / name, value[1])
    env = dict(os.environ, PYTHONFAULTHANDLER="")
    return subprocess.run(
        [sys.executable, "-m", "joulepath", *_argv(template, inp, out)],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )


def test_hostile_input_in_real_processes_never_crashes(tmp_path, model_folder):
    with ThreadPoolExecutor(max_workers=4) as pool:
        procs = list(
            pool.map(lambda k: _run_process(*SAMPLE[k], tmp_path / str(k), model_folder), range(len(SAMPLE)))
        )
    for (template, _), proc in zip(SAMPLE, procs, strict=True):
        assert 0 <= proc.returncode < 128, (template, proc.returncode, proc.stderr[-2000:])
        assert "Traceback" not in proc.stderr, (template, proc.stderr[-2000:])
        assert proc.returncode in (0, 2), (template, proc.returncode, proc.stderr[-2000:])
