"""pvtc from Python: compile G-code, DXF drawings and point-time series into
position-velocity-time (PVT) motion, with numpy arrays in and out.

Every call runs the same library code as the ``pvtc`` command: the options are the
CLI's options with the same names (``_`` for ``-``) and defaults, ``Program.write``
writes byte for byte what ``pvtc compile`` writes, and ``check`` reports what
``pvtc check --json`` prints.
"""

import os
from typing import Any, Dict, Iterator, List, Literal, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, "os.PathLike[str]"]
Number = Union[int, float]
Source = Union[PathLike, "Text"]
ArrayLike = npt.ArrayLike

class PvtcError(Exception):
    """The base of pvtc's exceptions."""

class CompileError(PvtcError):
    """An input pvtc refuses. ``diagnostics`` lists every error with the CLI's stable
    code and its line and column; ``str()`` is the first."""

    diagnostics: List["Diagnostic"]

class InternalError(PvtcError):
    """A bug in pvtc: a Rust panic caught at the boundary."""

class PvtcWarning(UserWarning):
    """A warning of pvtc's; ``diagnostic`` is its ``Diagnostic``. ``-W error`` makes it
    fail, as ``--deny-warnings`` does (notes are never warnings)."""

    diagnostic: "Diagnostic"

class InputWarning(PvtcWarning):
    """A warning about the input (``pvtc::gcode::…``, ``pvtc::dxf::…``, ``pvtc::csv::…``)."""

class PlanWarning(PvtcWarning):
    """A warning about planning (``pvtc::plan::…``)."""

class OutputWarning(PvtcWarning):
    """A warning about the output format (``pvtc::emit::…``, ``pvtc::pmac::…``)."""

class Diagnostic:
    """One diagnostic, with the fields ``pvtc --diagnostics json`` prints. Repeats of
    one code are one diagnostic with their ``count``."""

    code: Optional[str]
    severity: Literal["error", "warning", "advice"]
    message: str
    path: Optional[str]
    line: Optional[int]
    column: Optional[int]
    help: Optional[str]
    count: int

class Text:
    """Source text held in memory."""

    text: str
    kind: Literal["gcode", "dxf", "csv"]
    name: str
    def __init__(
        self, text: str, kind: Literal["gcode", "dxf", "csv"] = "gcode", name: str = "<text>"
    ) -> None: ...

class Program:
    """A planned program as read-only numpy arrays (no Python object per piece)."""

    @property
    def t(self) -> npt.NDArray[np.float64]:
        """Piece durations, seconds, shape (N,)."""
    @property
    def p(self) -> npt.NDArray[np.float64]:
        """End positions, shape (N, axes)."""
    @property
    def v(self) -> npt.NDArray[np.float64]:
        """End velocities, units/s, shape (N, axes)."""
    @property
    def line(self) -> npt.NDArray[np.uint32]:
        """Source line of every piece, shape (N,)."""
    @property
    def contour(self) -> npt.NDArray[np.uint32]:
        """Contour index of every piece in the whole program, shape (N,)."""
    @property
    def start(self) -> npt.NDArray[np.float64]:
        """Where the axes are before the first piece, shape (axes,)."""
    @property
    def start_velocity(self) -> npt.NDArray[np.float64]:
        """Velocities before the first piece (non-zero only for a chunk cut inside a contour)."""
    @property
    def axes(self) -> Tuple[str, ...]:
        """Axis names in X Y Z A B C order."""
    @property
    def kind(self) -> Tuple[Literal["feed", "rapid"], ...]:
        """Kind of each contour of this program (contour ``first_contour + i``)."""
    @property
    def first_contour(self) -> int:
        """Index of the first contour in the whole program (0 but for a chunk)."""
    @property
    def units(self) -> Literal["mm", "in"]:
        """Units of the linear positions."""
    @property
    def interpolation(self) -> Literal["pvt", "pt"]:
        """Cubic PVT pieces, or straight PT pieces."""
    @property
    def total_time(self) -> float:
        """Sum of the piece durations, seconds."""
    @property
    def format(self) -> str:
        """The output format the program was planned for."""
    @property
    def source_name(self) -> str:
        """The input's name in diagnostics and headers."""
    @property
    def diagnostics(self) -> List[Diagnostic]:
        """The warnings and notes planning gave."""
    def __len__(self) -> int: ...
    def write(
        self,
        format: Optional[str] = None,
        path: Optional[PathLike] = None,
        *,
        pmac_program: Optional[int] = ...,
        pmac_coord: Optional[int] = ...,
        pmac_axis: Union[str, Sequence[str], None] = ...,
        pmac_rotary: Optional[int] = ...,
        pmac_events: Optional[Literal["comments", "commands"]] = ...,
        trigger_every: Union[str, float, None] = ...,
    ) -> Optional[str]:
        """Writes the program in ``format`` (default: the one planned for) exactly as
        ``pvtc compile --format FORMAT`` writes it: into ``path``, or returned."""
    def sample(
        self, period: float
    ) -> Tuple[
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
    ]:
        """``(time, position, velocity, acceleration)`` every ``period`` seconds, from
        the same cubics the controller builds."""

class Peak:
    """A peak value with where it happens."""

    value: float
    time: float
    piece: int
    line: int

class Violation:
    """A limit exceeded."""

    axis: str
    quantity: str
    value: float
    limit: float
    time: float
    piece: int
    line: int

class Report:
    """What a program's motion will do (``pvtc check --json``)."""

    total_time: float
    servo_period: float
    max_path_error: Optional[float]
    path_error: Optional[Peak]
    peaks: Dict[str, Dict[str, Peak]]
    speed: Optional[Dict[str, Any]]
    violations: List[Violation]
    exceeded: bool
    def as_dict(self) -> Dict[str, Any]:
        """The object ``pvtc check --json`` prints."""

class Chunks(Iterator[Program]):
    """The chunks of a program as it is planned."""

    @property
    def made(self) -> int:
        """Chunks the planner has filled: at most one more than taken."""
    def close(self) -> None:
        """Stops the stream."""
    def __iter__(self) -> "Chunks": ...
    def __next__(self) -> Program: ...

MachineSpec = Union[PathLike, Mapping[str, Any]]

def plan(
    source: Source,
    *,
    format: str = "pmac",
    input_format: Optional[Literal["gcode", "dxf", "csv"]] = ...,
    planner: Optional[str] = ...,
    machine: Optional[MachineSpec] = ...,
    tolerance: Optional[Number] = ...,
    corner_tolerance: Optional[Number] = ...,
    quantize: Optional[Number] = ...,
    quantize_rounding: Optional[Literal["up", "nearest"]] = ...,
    time_slice: Optional[Number] = ...,
    accel: Optional[Number] = ...,
    feed: Optional[Number] = ...,
    rapid: Optional[Number] = ...,
    units: Optional[Literal["mm", "in"]] = ...,
    counts_per_unit: Optional[Mapping[str, Number]] = ...,
    offsets: Optional[PathLike] = ...,
    tool_table: Optional[PathLike] = ...,
    tool_table_units: Optional[Literal["mm", "in"]] = ...,
    subroutine_path: Union[PathLike, Sequence[PathLike], None] = ...,
    hal: Optional[Mapping[str, Number]] = ...,
    probe_results: Optional[Sequence[Sequence[Number]]] = ...,
    arc_abs_tolerance: Optional[Number] = ...,
    arc_rel_tolerance: Optional[Number] = ...,
    layers: Union[str, Sequence[str], None] = ...,
    join_tolerance: Optional[Number] = ...,
    start_point: Optional[Sequence[Number]] = ...,
    safe_z: Optional[Number] = ...,
    max_points: Optional[int] = ...,
    velocities: Optional[Literal["file", "plan"]] = ...,
) -> Program:
    """Plans ``source`` (a path or ``Text``) into a ``Program``, as ``pvtc compile`` plans it."""

def from_points(
    positions: ArrayLike,
    times: ArrayLike,
    velocities: Optional[ArrayLike] = None,
    *,
    axes: Sequence[str] = ("X", "Y"),
    planner: str = "spline",
    **options: Any,
) -> Program:
    """Plans a point-time series from arrays, as the CSV front end plans the same points."""

def check(
    program_or_source: Union[Program, Source],
    machine: Optional[MachineSpec] = None,
    servo_period: Optional[float] = None,
    **options: Any,
) -> Report:
    """What the motion will do, as ``pvtc check --json`` reports it."""

def stream(source: Union[Source, Program], chunk: int = 4000, **options: Any) -> Chunks:
    """``Program`` chunks of at most ``chunk`` pieces, yielded while planning goes on."""
