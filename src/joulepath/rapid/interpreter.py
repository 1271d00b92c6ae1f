"""Run a RAPID task as the controller would, to find the motion of one cycle.

The interpreter walks the typed tree (:mod:`joulepath.rapid.nodes`) with its state held
explicitly: the task's data (module scope, ``LOCAL`` data per module), an environment per
routine call (parameters by reference for ``INOUT`` / ``VAR`` / ``PERS``, by value for
``IN``), typed values with RAPID's rules (:mod:`joulepath.rapid.values`), the motion
settings in force (``AccSet``, ``VelSet``, ``GripLoad``, ``ConfJ`` / ``ConfL``, ``SingArea``,
``PDispSet``), and one step budget checked in one place (:meth:`Machine.tick`).

**Known and unknown.** What the program learns only while it runs (digital, group and
analog inputs, ``WaitDI`` / ``WaitUntil``, socket and vision data, operator input, another
task's data, a random number) comes from the scenario (``io``) where the user gives it.
Where not, it takes a stand-in (an input reads 0, a received string is empty, a variable
keeps the value it holds) and is *marked*: every value carries the set of reasons it is
not certain, which flows through expressions, assignments and calls. A branch or loop
decided by a marked condition runs its stand-in choice with everything inside marked,
and the first move after it (whose start depends on that choice) is marked too. A move
with a marked target, speed, zone, tool or context is kept as taught by the optimizer,
and the report names it with the reasons. Only text that is not RAPID, a name declared
nowhere, an unreachable target and a program that never ends are refused
(:class:`~joulepath.rapid.RapidError`, one line ``file:line: what; how to fix``).

**The cycle.** The program runs from ``main`` (or the routine given). The first endless
loop it enters (``WHILE TRUE``, or ``WHILE`` on a ``bool`` no statement assigns) is the
production loop: a turn of it is the cycle (the second: it starts where a turn ends, with the
motion settings a turn leaves, as every later one does); what ran before it is the way there.
Without such a loop the cycle is one run of the routine. ``TRAP`` routines and ``ERROR`` /
``UNDO`` / ``BACKWARD`` handlers are read and kept, never run.

**The layout.** The interpreter dispatches by node type, in the way of :class:`ast.NodeVisitor`:
:class:`~joulepath.rapid._machine.Machine` holds the state and resolves names;
:mod:`~joulepath.rapid._expressions` and :mod:`~joulepath.rapid._statements` hold one handler per
node type (:data:`EXPRESSIONS`, :data:`STATEMENTS`), plugged in here; a call goes by the name it calls
to a routine of the task (:mod:`~joulepath.rapid._routines`), a move
(:mod:`~joulepath.rapid._motion`), a built-in instruction or function
(:mod:`~joulepath.rapid._instructions`, :mod:`~joulepath.rapid._functions`), or the documented table
(:mod:`joulepath.rapid.builtins`).
"""

from __future__ import annotations

import sys

from joulepath.errors import RapidError
from joulepath.rapid import nodes as n
from joulepath.rapid._expressions import EXPRESSIONS
from joulepath.rapid._machine import Machine, inputs_read
from joulepath.rapid._motion import target_flange
from joulepath.rapid._routines import invoke
from joulepath.rapid._scan import listed, moves_in
from joulepath.rapid._state import (
    MAX_DEPTH,
    MAX_LOOP_TURNS,
    MAX_SECONDS,
    MAX_STEPS,
    SPEEDS,
    SPIN_TURNS,
    UNKNOWN_TARGET,
    UNTYPED,
    ZONES,
    CycleRestart,
    Frame,
    GotoLabel,
    ReturnValue,
    StopRun,
)
from joulepath.rapid._statements import STATEMENTS
from joulepath.rapid._trace import Action, Event, Kinematics, Motion, MotionSettings, Taint, Trace, Wait

__all__ = [
    "MAX_DEPTH",
    "MAX_LOOP_TURNS",
    "MAX_SECONDS",
    "MAX_STEPS",
    "SPEEDS",
    "SPIN_TURNS",
    "UNKNOWN_TARGET",
    "UNTYPED",
    "ZONES",
    "Action",
    "Event",
    "Interpreter",
    "Kinematics",
    "Motion",
    "MotionSettings",
    "Taint",
    "Trace",
    "Wait",
    "inputs_read",
    "listed",
    "moves_in",
    "target_flange",
]


RESTARTS = 3
"""``ExitCycle`` before any move starts ``main`` again at most this many times (a first-run set-up)."""


class Interpreter(Machine):
    """One run of a task: :meth:`run` gives the :class:`Trace` (see the module's docstring)."""

    expressions = EXPRESSIONS
    statements = STATEMENTS
    restarted = 0
    """The event where the last start of ``main`` after ``ExitCycle`` began (0: none)."""

    def _run_main(self, r: n.Routine, m: n.Module) -> None:
        """``main`` run as the controller runs it: an ``ExitCycle`` reached before any move (a first
        run that sets a flag and breaks the cycle) starts it again from its first statement, the
        data kept, and the cycle is that next run; one after a move ends the cycle there."""
        for _ in range(RESTARTS):
            start = len(self.events)
            try:
                invoke(self, r, m, (), r.pos)
                return
            except CycleRestart as stop:
                if self.cycle_end is not None or any(isinstance(e, Motion) for e in self.events[start:]):
                    raise
                self.note(
                    f"{stop.why} before any move: main starts again, its data kept (as the controller does)"
                )
                self.stack = [Frame(None, m, {}, set(), m.name)]
                self.restarted = len(self.events)
        invoke(self, r, m, (), r.pos)

    def run(self, routine: str | None = None) -> Trace:
        name = routine or "main"
        found = self.routines.get(name.lower())
        if found is None:
            for m in self.task.modules:
                found = self.local_routines[m.name.lower()].get(name.lower()) or found
        if found is None:
            table = {k: r for k, (r, _) in self.routines.items()}
            movers = sorted(
                {r.name for r, _ in self.routines.values() if r.kind == "PROC" and moves_in(r, table)}
            )
            where = f"{self.task.modules[0].path}:{self.task.modules[0].pos.line}"
            which = (
                f"give --routine NAME, one of the routines that move the robot: {listed(movers)}"
                if movers
                else "no routine of it moves the robot (no move instruction in what was given)"
            )
            if routine is None:
                raise RapidError(f"{where}: no main routine in {self.task.source}; {which}")
            raise RapidError(f"{where}: no routine {routine} in {self.task.source}; {which}")
        r, m = found
        if r.kind != "PROC" or any(not p.optional for p in r.params):
            raise RapidError(
                f"{r.pos}: {r.name} is a {r.kind} with required parameters; give a PROC that runs on its own"
            )
        for k in self.io:
            if (
                k not in self.signals_used
                and k not in self.globals
                and not any(k in loc for loc in self.locals_of.values())
            ):
                raise RapidError(
                    f"--io {k}: the program reads no signal or data of that name; "
                    "give a name the program uses"
                )
        self.stack = [Frame(None, m, {}, set(), m.name)]
        limit = sys.getrecursionlimit()
        sys.setrecursionlimit(max(limit, 20 * MAX_DEPTH + 2000))
        try:
            self._run_main(r, m)
        except StopRun as stop:
            if self.cycle_end is None:
                self.note(stop.why)
        except GotoLabel as g:
            raise RapidError(
                f"{g.pos}: GOTO {g.label}: no such label in the routine; add the label"
            ) from None
        except ReturnValue:
            pass
        except RecursionError:
            raise RapidError(
                f"{self.task.source}: an expression or a chain of calls runs deeper than this interpreter "
                "follows; split long expressions into shorter statements"
            ) from None
        finally:
            sys.setrecursionlimit(limit)
        end = self.cycle_end if self.cycle_end is not None else len(self.events)
        if self.restarted:
            self.cycle_start = max(self.cycle_start, self.restarted)
        return Trace(
            tuple(self.events),
            self.cycle_start,
            end,
            tuple(self.notes),
            r.name,
            self.loop,
            self.steps,
            tuple(self.assumed),
        )
