"""One line on stderr, always (issue 25, item 5): library warnings never come before the error line.

Warnings raised while a command runs (NumPy's RuntimeWarnings, ...) are held back by
``main``: after an error only the error line is printed; after success they are shown
as the warning filters say. C libraries cannot be held back that way, so what makes
them print (coal's "eigen: too many iterations" on a NaN vertex) is refused first.
"""

from __future__ import annotations

import struct
import subprocess
import sys
import warnings

import numpy as np
import pytest

import joulepath.cli._robot as robot_cli
from joulepath.cli import main
from joulepath.errors import InvalidInput

POSITION_1E999 = """MODULE P
    CONST robtarget p1 := [[1E999, 0, 630], [0.5, 0, 0.866, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST jointtarget J1 := [[10, 0, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        MoveAbsJ J1, v1000, fine, tool0;
        MoveJ p1, v1000, fine, tool0;
    ENDPROC
ENDMODULE
"""

TETRAHEDRON = 0.1 * np.array(
    [
        [[0, 0, 0], [1, 0, 0], [0, 1, 0]],
        [[0, 0, 0], [1, 0, 0], [0, 0, 1]],
        [[0, 0, 0], [0, 1, 0], [0, 0, 1]],
        [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
    ]
)


def _binary_stl(triangles: np.ndarray) -> bytes:
    out = b"\0" * 80 + struct.pack("<I", len(triangles))
    for tri in triangles:
        out += struct.pack("<3f", 0, 0, 0) + tri.astype("<f4").tobytes() + b"\0\0"
    return out


def _one_line(capfd, args, fragment):
    """Exit 2 and one line, on the file descriptor (what C libraries print is caught too)."""
    assert main(args) == 2
    err = capfd.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert fragment in err, err
    return err


def test_a_warning_before_an_error_is_not_printed(capfd, monkeypatch):
    def warns_then_fails(*args, **kwargs):
        np.log(np.zeros(1))  # RuntimeWarning: divide by zero
        raise InvalidInput("the real problem")

    monkeypatch.setattr(robot_cli, "parse_joints", warns_then_fails)
    _one_line(capfd, ["robot", "fk", "irb120", "--q", "0,0,0,0,0,0"], "error: the real problem")


def test_a_warning_of_a_successful_command_is_shown_once(monkeypatch):
    real = robot_cli.parse_joints

    def warns(*args, **kwargs):
        for _ in range(3):
            np.log(np.zeros(1))
        return real(*args, **kwargs)

    monkeypatch.setattr(robot_cli, "parse_joints", warns)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(["robot", "fk", "irb120", "--q", "0,0,0,0,0,0"]) == 0
    assert [str(w.message) for w in caught] == ["divide by zero encountered in log"]


def test_a_position_of_1e999_is_one_line(tmp_path, capfd):
    program = tmp_path / "p.mod"
    program.write_text(POSITION_1E999)
    _one_line(capfd, ["cycle", str(program), "--out", str(tmp_path / "run")], "p.mod:")
    assert not (tmp_path / "run").exists()


def test_a_tiny_stribeck_speed_is_one_line(tmp_path, capfd):
    from joulepath.sim import simulate

    log = simulate(tmp_path / "l.csv", plant="lab", n_moves=4, seed=1).log
    _one_line(
        capfd, ["identify", str(log), "--stribeck-speed", "1e-300", "--out", str(tmp_path / "t")], "Stribeck"
    )
    assert not (tmp_path / "t").exists()


@pytest.mark.parametrize("kind", ["stl", "obj"])
def test_a_nan_vertex_is_refused_before_coal_sees_it(tmp_path, capfd, kind):
    mesh = tmp_path / f"m.{kind}"
    if kind == "stl":
        bad = TETRAHEDRON.copy()
        bad[1, 2, 0] = np.nan
        mesh.write_bytes(_binary_stl(bad))
    else:
        mesh.write_text("v 0 0 0\nv 0.1 0 0\nv 0 nan 0\nv 0 0 0.1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n")
    cell = tmp_path / "cell.toml"
    cell.write_text(f'[[mesh]]\nname = "m"\nfile = "{mesh.name}"\ncenter_mm = [600, 0, 0]\n')
    program = tmp_path / "c.toml"
    program.write_text("[[step]]\njoints_deg = [10, 0, 0, 0, 30, 0]\nduration_s = 1\n")
    args = ["cycle", str(program), "--cell", str(cell), "--out", str(tmp_path / "run")]
    err = _one_line(capfd, args, "has vertices that are not finite numbers")
    assert "eigen" not in err


def test_a_finite_mesh_still_loads(tmp_path):
    from joulepath.program._cell import read_cell

    (tmp_path / "m.stl").write_bytes(_binary_stl(TETRAHEDRON))
    (tmp_path / "cell.toml").write_text('[[mesh]]\nname = "m"\nfile = "m.stl"\ncenter_mm = [600, 0, 0]\n')
    assert read_cell(tmp_path / "cell.toml").obstacles[0].kind == "mesh"


def test_subprocess_position_1e999_prints_one_line(tmp_path):
    """The installed entry point, as a user runs it: no warning printed before the error."""
    program = tmp_path / "p.mod"
    program.write_text(POSITION_1E999)
    proc = subprocess.run(
        [sys.executable, "-m", "joulepath", "cycle", str(program), "--out", str(tmp_path / "run")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2, proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert proc.stderr.startswith("error: ")
