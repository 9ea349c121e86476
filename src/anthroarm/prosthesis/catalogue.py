"""Motor and gearbox catalogues (CSV) for actuator sizing.

Two CSV files, one row per product, ``#`` lines are comments (the source of the data goes
there).  The units are the catalogue's own (the units of manufacturers' data sheets) and are
part of the column names; :func:`load` converts every value to SI.

``motors.csv`` columns::

    name, series, diameter_mm, nominal_voltage_V, terminal_resistance_ohm,
    torque_constant_mNm_per_A, rotor_inertia_gcm2, max_continuous_torque_mNm,
    max_speed_rpm, mass_g

``gearboxes.csv`` columns::

    name, series, motor_diameters_mm (';'-separated), stages, ratio, efficiency,
    max_continuous_torque_Nm, max_intermittent_torque_Nm, max_input_speed_rpm, mass_g

A gearbox mounts on a motor whose diameter is one of its ``motor_diameters_mm``.  Extra columns
are kept out of the model and allowed.

The example catalogue shipped in ``anthroarm/data/actuators/`` holds representative values in the
style of maxon motor ag's published data sheets for small brushed DC motors (RE, DCX) and
planetary gearheads (GP) — rounded and approximated, not a verified transcription (the files'
header comments say so and cite the catalogue).  Bad files raise
:class:`~anthroarm.errors.CatalogueError` naming the file, the line and the column.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from .._io import read_bounded
from ..control.motor import DCMotor
from ..errors import CatalogueError

RPM = 2.0 * math.pi / 60.0  # rad/s per rpm

MOTOR_COLUMNS = (
    "name",
    "series",
    "diameter_mm",
    "nominal_voltage_V",
    "terminal_resistance_ohm",
    "torque_constant_mNm_per_A",
    "rotor_inertia_gcm2",
    "max_continuous_torque_mNm",
    "max_speed_rpm",
    "mass_g",
)
GEARBOX_COLUMNS = (
    "name",
    "series",
    "motor_diameters_mm",
    "stages",
    "ratio",
    "efficiency",
    "max_continuous_torque_Nm",
    "max_intermittent_torque_Nm",
    "max_input_speed_rpm",
    "mass_g",
)


@dataclass(frozen=True)
class Motor:
    """One DC motor of a catalogue, SI units.

    ``diameter`` m, ``V_nom`` V, ``R`` Ω, ``k_m`` N·m/A, ``J_m`` kg·m², ``tau_cont`` N·m (rated
    continuous torque, the thermal limit), ``max_speed`` rad/s, ``mass`` kg."""

    name: str
    series: str
    diameter: float
    V_nom: float
    R: float
    k_m: float
    J_m: float
    tau_cont: float
    max_speed: float
    mass: float

    def dc_motor(self, gearbox: "Gearbox | None" = None):
        """This motor behind ``gearbox`` (or direct drive) as the servo model
        :class:`anthroarm.control.motor.DCMotor` (Eq. (9-1); no inductance, no viscous friction:
        the catalogue gives neither)."""
        i, eta = (1.0, 1.0) if gearbox is None else (gearbox.ratio, gearbox.efficiency)
        name = self.name if gearbox is None else f"{self.name} + {gearbox.name}"
        return DCMotor(
            R=self.R,
            k_m=self.k_m,
            J_m=self.J_m,
            i=i,
            eta=eta,
            V_nom=self.V_nom,
            tau_cont=self.tau_cont,
            name=name,
        )


@dataclass(frozen=True)
class Gearbox:
    """One gearbox of a catalogue, SI units.

    ``motor_diameters`` m, ``ratio`` motor speed / output speed, ``efficiency`` in (0, 1],
    ``tau_cont`` / ``tau_max`` the output's continuous / intermittent torque ratings N·m,
    ``max_input_speed`` rad/s, ``mass`` kg."""

    name: str
    series: str
    motor_diameters: tuple
    stages: int
    ratio: float
    efficiency: float
    tau_cont: float
    tau_max: float
    max_input_speed: float
    mass: float

    def fits(self, motor: Motor) -> bool:
        """True when the gearbox mounts on ``motor`` (its diameter is one of ours, to 0.1 mm)."""
        return any(abs(d - motor.diameter) < 1e-4 for d in self.motor_diameters)


@dataclass(frozen=True)
class Catalogue:
    """Motors and gearboxes, and the files they came from."""

    motors: tuple
    gearboxes: tuple
    motor_source: str = ""
    gearbox_source: str = ""

    def combinations(self):
        """Every (motor, gearbox) pair that mounts together."""
        return [(m, g) for m in self.motors for g in self.gearboxes if g.fits(m)]


def default_paths() -> tuple[Path, Path]:
    """The shipped example catalogue: (motors.csv, gearboxes.csv)."""
    base = resources.files("anthroarm") / "data" / "actuators"
    return Path(str(base / "motors.csv")), Path(str(base / "gearboxes.csv"))


#: the largest catalogue file read (bytes); a manufacturer's catalogue of a few hundred products
#: is tens of kB
MAX_FILE_BYTES = 16 * 2**20
#: the most products of one file (the sizing tries every motor with every gearbox)
MAX_ROWS = 10_000


def _read(path) -> str:
    """The text of the regular file ``path`` (at most :data:`MAX_FILE_BYTES`; ``/dev/zero``, a
    folder or a FIFO is refused unread), else :class:`~anthroarm.errors.CatalogueError`."""
    data = read_bounded(
        path,
        MAX_FILE_BYTES,
        error=lambda problem: CatalogueError(problem, path),
        what="CSV catalogue",
        encoding=None,
    )
    try:
        text = data.decode("utf-8-sig")  # a spreadsheet may write a BOM
    except UnicodeDecodeError:
        raise CatalogueError("not a UTF-8 text file", path) from None
    if "\x00" in text:
        raise CatalogueError("holds NUL bytes: not a CSV text file", path)
    return text


def _rows(path, columns):
    """(line number, dict) per data row; checks the header."""
    path = Path(path)
    text = _read(path)
    numbered = [
        (k + 1, line)
        for k, line in enumerate(text.splitlines())
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not numbered:
        raise CatalogueError("no header line (the file is empty or only comments)", path)
    if len(numbered) > MAX_ROWS + 1:
        raise CatalogueError(
            f"{len(numbered) - 1} rows, more than {MAX_ROWS} products (the bound of one file)", path
        )
    reader = csv.reader(io.StringIO("\n".join(line for _, line in numbered)))
    try:
        lines = list(reader)
    except csv.Error as exc:  # a field beyond csv's size limit, a broken quote
        raise CatalogueError(f"not a readable CSV file ({exc})", path) from None
    header = [h.strip() for h in lines[0]]
    missing = [c for c in columns if c not in header]
    if missing:
        raise CatalogueError(
            f"missing column(s) {missing}; the header has {header}; required: {list(columns)}",
            path,
            numbered[0][0],
            missing[0],
        )
    if len(set(header)) != len(header):
        raise CatalogueError(f"duplicate column names in the header {header}", path, numbered[0][0])
    out = []
    for (lineno, _), fields in zip(numbered[1:], lines[1:]):
        if len(fields) != len(header):
            raise CatalogueError(
                f"{len(fields)} fields, the header has {len(header)}", path, lineno
            )
        out.append((lineno, dict(zip(header, (f.strip() for f in fields)))))
    if not out:
        raise CatalogueError("no rows (a catalogue needs at least one product)", path)
    return out


#: largest value of any catalogue number in its column's own unit, e.g. rpm or g; beyond it a
#: value is a typo, and the sizing's equations would overflow
UPPER = 1e6


def _number(row, col, path, lineno, *, positive=True, upper=UPPER) -> float:
    text = row[col]
    try:
        v = float(text)
    except ValueError:
        raise CatalogueError(f"{col} = {text!r} is not a number", path, lineno, col) from None
    if not math.isfinite(v):
        raise CatalogueError(f"{col} = {text!r} is not finite", path, lineno, col)
    if positive and v <= 0.0:
        raise CatalogueError(f"{col} = {v:g} must be > 0 (a physical constant)", path, lineno, col)
    if v > upper:
        raise CatalogueError(
            f"{col} = {v:g} must be <= {upper:g} (in the column's unit; a typo?)", path, lineno, col
        )
    return v


def _name(row, path, lineno, seen) -> str:
    name = row["name"]
    if not name:
        raise CatalogueError("empty name", path, lineno, "name")
    if name in seen:
        raise CatalogueError(
            f"duplicate name {name!r} (also on line {seen[name]})", path, lineno, "name"
        )
    seen[name] = lineno
    return name


def load_motors(path=None) -> tuple:
    """Motors of a CSV file (default: the shipped example), SI units; see the module docstring."""
    path = Path(path) if path is not None else default_paths()[0]
    seen: dict = {}
    out = []
    for lineno, r in _rows(path, MOTOR_COLUMNS):
        n = lambda c, **kw: _number(r, c, path, lineno, **kw)  # noqa: E731
        out.append(
            Motor(
                name=_name(r, path, lineno, seen),
                series=r["series"],
                diameter=n("diameter_mm") * 1e-3,
                V_nom=n("nominal_voltage_V"),
                R=n("terminal_resistance_ohm"),
                k_m=n("torque_constant_mNm_per_A") * 1e-3,
                J_m=n("rotor_inertia_gcm2") * 1e-7,
                tau_cont=n("max_continuous_torque_mNm") * 1e-3,
                max_speed=n("max_speed_rpm") * RPM,
                mass=n("mass_g") * 1e-3,
            )
        )
    return tuple(out)


def load_gearboxes(path=None) -> tuple:
    """Gearboxes of a CSV file (default: the shipped example), SI units; see the module docstring."""
    path = Path(path) if path is not None else default_paths()[1]
    seen: dict = {}
    out = []
    for lineno, r in _rows(path, GEARBOX_COLUMNS):
        n = lambda c, **kw: _number(r, c, path, lineno, **kw)  # noqa: E731
        diams = []
        for part in r["motor_diameters_mm"].split(";"):
            try:
                d = float(part)
            except ValueError:
                raise CatalogueError(
                    f"motor_diameters_mm = {r['motor_diameters_mm']!r} is not a ';'-separated list "
                    "of numbers",
                    path,
                    lineno,
                    "motor_diameters_mm",
                ) from None
            if not (math.isfinite(d) and 0 < d <= UPPER):
                raise CatalogueError(
                    f"motor_diameters_mm has {part!r}; diameters must be > 0 mm",
                    path,
                    lineno,
                    "motor_diameters_mm",
                )
            diams.append(d * 1e-3)
        stages = n("stages")
        if stages != int(stages):
            raise CatalogueError(
                f"stages = {stages:g} must be a whole number", path, lineno, "stages"
            )
        tc, tm = n("max_continuous_torque_Nm"), n("max_intermittent_torque_Nm")
        if tm < tc:
            raise CatalogueError(
                f"max_intermittent_torque_Nm = {tm:g} is below max_continuous_torque_Nm = {tc:g}",
                path,
                lineno,
                "max_intermittent_torque_Nm",
            )
        out.append(
            Gearbox(
                name=_name(r, path, lineno, seen),
                series=r["series"],
                motor_diameters=tuple(diams),
                stages=int(stages),
                ratio=n("ratio"),
                efficiency=n("efficiency", upper=1.0),
                tau_cont=tc,
                tau_max=tm,
                max_input_speed=n("max_input_speed_rpm") * RPM,
                mass=n("mass_g") * 1e-3,
            )
        )
    return tuple(out)


def load(motors=None, gearboxes=None) -> Catalogue:
    """A :class:`Catalogue` from two CSV files (default: the shipped example catalogue)."""
    mp, gp = default_paths()
    mp = Path(motors) if motors is not None else mp
    gp = Path(gearboxes) if gearboxes is not None else gp
    cat = Catalogue(load_motors(mp), load_gearboxes(gp), str(mp), str(gp))
    if not cat.combinations():
        raise CatalogueError(
            f"no gearbox of {gp} mounts on any motor of {mp} (compare diameter_mm with "
            "motor_diameters_mm)",
            gp,
        )
    return cat


def source_note(path) -> str:
    """The ``#`` comment lines at the top of a catalogue file (its source), joined."""
    lines = []
    for line in _read(path).splitlines():
        if not line.lstrip().startswith("#"):
            break
        lines.append(line.lstrip()[1:].strip())
    return " ".join(lines)
