"""Where a robot model's parameters come from, and how sure each is (``<name>.provenance.toml``).

A provenance file sits beside a robot description (``irb4600-40-2.55.irml`` ->
``irb4600-40-2.55.provenance.toml``). It says, per parameter group, its kind
(:data:`KINDS`: published, identified, estimated, assumed), its source, how it was obtained and
a bound; and, for the Monte Carlo statement of a saving, numeric bounds on the link masses,
centres of mass and inertias (:class:`Uncertainty`). Layout::

    robot = "irb4600-40-2.55"
    name = "IRB 4600-40/2.55"
    family = "irb4600"
    family_default = true
    status = "estimated"          # the weakest kind among the parameters that shape the dynamics
    notes = ["..."]
    [uncertainty]
    link_mass_rel = 0.7           # each link's mass within ±70 %
    link_com_m = 0.127            # each centre of mass within ±0.127 m per axis
    link_inertia_rel = 0.7        # each inertia within ±70 % (scaled with its mass)
    catalogue_mass_rel = 0.05     # the catalogue's manipulator mass within ±5 %
    [[parameter]]
    name = "link masses"  kind = "estimated"  source = "..."  how = "..."  bound = "±70 % each"
"""

from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass
from pathlib import Path

from joulepath.errors import InvalidRobotDescription

PROVENANCE_SUFFIX = ".provenance.toml"
KINDS = ("published", "identified", "estimated", "assumed")
"""From the surest to the least sure."""


@dataclass(frozen=True, slots=True, kw_only=True)
class ParameterSource:
    """One parameter group of a model: its kind, source, how it was obtained and its bound."""

    name: str
    kind: str
    source: str
    how: str
    bound: str

    def line(self) -> str:
        return f"{self.name}: {self.kind}, {self.bound}; {self.source}; {self.how}"


@dataclass(frozen=True, slots=True, kw_only=True)
class Uncertainty:
    """Numeric bounds of a model's estimated dynamics (all ≥ 0; zero: the nominal model only).

    Attributes
    ----------
    link_mass_rel : float
        Each moving link's mass lies within ``(1 ± link_mass_rel)`` times the nominal one.
    link_com_m : float
        Each centre of mass lies within ± this (m) of the nominal one, per axis.
    link_inertia_rel : float
        Each inertia tensor (about the centre of mass) lies within ``(1 ± link_inertia_rel)``
        times the nominal one.
    catalogue_mass_rel : float
        The catalogue's manipulator mass is known to within this fraction.
    """

    link_mass_rel: float = 0.0
    link_com_m: float = 0.0
    link_inertia_rel: float = 0.0
    catalogue_mass_rel: float = 0.0

    def __post_init__(self) -> None:
        for key in ("link_mass_rel", "link_com_m", "link_inertia_rel", "catalogue_mass_rel"):
            value = getattr(self, key)
            if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
                raise InvalidRobotDescription(f"uncertainty {key} = {value!r}: expected a finite number ≥ 0")
        for key in ("link_mass_rel", "link_inertia_rel"):
            if getattr(self, key) >= 1.0:
                raise InvalidRobotDescription(
                    f"uncertainty {key} = {getattr(self, key)!r}: expected < 1 "
                    "(a mass or inertia stays positive)"
                )

    @property
    def is_zero(self) -> bool:
        return self.link_mass_rel == 0 and self.link_com_m == 0 and self.link_inertia_rel == 0


@dataclass(frozen=True, slots=True, kw_only=True)
class ModelProvenance:
    """Everything a provenance file says about a robot model."""

    robot: str
    name: str
    family: str = ""
    family_default: bool = False
    status: str
    notes: tuple[str, ...] = ()
    uncertainty: Uncertainty = Uncertainty()
    parameters: tuple[ParameterSource, ...] = ()
    source: str = ""

    @property
    def is_estimate(self) -> bool:
        """True when the model's dynamics rest on estimates or assumptions (not published or identified)."""
        return self.status in ("estimated", "assumed")

    def headline(self) -> str:
        """One line that goes with every result computed on this model."""
        if not self.is_estimate:
            return f"model {self.name}: {self.status}"
        u = self.uncertainty
        return (
            f"model {self.name} is {self.status.upper()}: link masses ±{u.link_mass_rel:.0%}, "
            f"centres of mass ±{u.link_com_m * 1000:.0f} mm, inertias ±{u.link_inertia_rel:.0%} "
            "(joulepath robot show lists every source; identify a twin from the arm's log to replace them)"
        )

    def lines(self) -> list[str]:
        """What ``joulepath robot show`` prints."""
        out = [f"provenance ({self.source}): status {self.status}"]
        out += [f"  {p.line()}" for p in self.parameters]
        out += [f"  note: {n}" for n in self.notes]
        return out


def _fail(where: str, problem: str) -> InvalidRobotDescription:
    return InvalidRobotDescription(f"{where}: {problem}")


def read_provenance(path: str | os.PathLike[str]) -> ModelProvenance:
    """Read a provenance file.

    Raises
    ------
    InvalidRobotDescription
        Unreadable file, not TOML, a missing key, an unknown kind, a negative bound.
    """
    p = Path(path)
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except OSError as err:
        raise _fail(str(p), f"cannot be read ({err.strerror})") from err
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as err:
        raise _fail(str(p), f"is not valid TOML ({err})") from err
    for key in ("robot", "name", "status"):
        if not isinstance(data.get(key), str):
            raise _fail(str(p), f"missing {key!r} (a string)")
    if data["status"] not in KINDS:
        raise _fail(str(p), f"status {data['status']!r} is not one of {', '.join(KINDS)}")
    params = []
    for i, entry in enumerate(data.get("parameter", [])):
        where = f"{p} [[parameter]] #{i + 1}"
        missing = [k for k in ("name", "kind", "source", "how", "bound") if not isinstance(entry.get(k), str)]
        if missing:
            raise _fail(where, f"missing {', '.join(missing)} (strings)")
        if entry["kind"] not in KINDS:
            raise _fail(where, f"kind {entry['kind']!r} is not one of {', '.join(KINDS)}")
        params.append(ParameterSource(**{k: entry[k] for k in ("name", "kind", "source", "how", "bound")}))
    unc = data.get("uncertainty", {})
    known = {"link_mass_rel", "link_com_m", "link_inertia_rel", "catalogue_mass_rel"}
    unknown = sorted(set(unc) - known)
    if unknown:
        raise _fail(
            f"{p} [uncertainty]", f"unknown key(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}"
        )
    try:
        uncertainty = Uncertainty(**{k: float(v) for k, v in unc.items()})
    except (TypeError, ValueError) as err:
        raise _fail(f"{p} [uncertainty]", f"not numbers ({err})") from err
    except InvalidRobotDescription as err:
        raise _fail(f"{p} [uncertainty]", str(err)) from err
    return ModelProvenance(
        robot=data["robot"],
        name=data["name"],
        family=str(data.get("family", "")),
        family_default=bool(data.get("family_default", False)),
        status=data["status"],
        notes=tuple(str(n) for n in data.get("notes", [])),
        uncertainty=uncertainty,
        parameters=tuple(params),
        source=str(p),
    )


def provenance_path(description: str | os.PathLike[str]) -> Path:
    """The provenance file that belongs beside a robot description file (it may not exist)."""
    p = Path(description)
    return p.with_name(p.stem + PROVENANCE_SUFFIX)


def provenance_beside(description: str | os.PathLike[str] | None) -> ModelProvenance | None:
    """The provenance of a robot description file, or None when it has none beside it."""
    if description is None:
        return None
    path = provenance_path(description)
    return read_provenance(path) if path.is_file() else None
