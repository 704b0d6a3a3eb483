"""stackbeam: vibration of stacked leaf springs with Coulomb friction between the leaves
(K. Lee & C.-H. Lim 1992), from Python. docs/python.md.

    import stackbeam
    scenario = stackbeam.load_scenario("scenarios/paper_friction.toml")
    scenario.model.leaves[0].height_m = 0.006          # the scenario file's key paths
    result = stackbeam.simulate(scenario, t_end_s=1.0)  # SimulationOptions members
    result["t"], result["w"]                            # the CSV's columns, numpy arrays
    result.summary["energy_j"]["dissipated"]            # the JSON summary of the command line

Names: ``scenario.model.<key path>`` is the scenario file's key (``leaves[2].height_m``,
``loading.force_n.amplitude``, ``mesh.symmetry``); ``scenario.simulation.<member>`` is the
member of SimulationOptions, the file's ``integrator.<member>`` (``cvode.rtol``).
"""
import json as _json
import os as _os
from collections.abc import Mapping as _Mapping

from ._core import (
    InputError,
    InputTypeError,
    ThreadStartError,
    SolverError,
    Scenario,
    Leaf,
    LeafProfile,
    LeafEnd,
    Interface,
    Clamp,
    Clip,
    Probe,
    TimeFunction,
    load_scenario,
    paper_example,
    option_table,
    step_record_columns,
    export_fmu,
)
from . import _core

__all__ = [
    "InputError", "InputTypeError", "ThreadStartError", "SolverError", "Scenario", "Leaf", "LeafProfile", "LeafEnd", "Interface", "Clamp", "Clip",
    "Probe", "TimeFunction", "load_scenario", "paper_example", "option_table", "simulate", "make_stepper",
    "sweep", "SweepResult", "MAX_SWEEP_JOBS", "fit",
    "Result", "Stepper", "export_fmu",
]


def _fields_repr(obj):
    """ClassName(key=value, ...) of a scenario's entry: its public attributes, lists by their length."""
    parts = []
    for name in dir(obj):
        if name.startswith("_"):
            continue
        value = getattr(obj, name)
        if callable(value):
            continue
        if hasattr(value, "__len__") and not isinstance(value, (str, list)):
            value = "[%d]" % len(value)
        elif type(value).__module__.startswith("stackbeam"):
            value = "..."
        else:
            value = repr(value)
        parts.append("%s=%s" % (name, value))
    return "%s(%s)" % (type(obj).__name__, ", ".join(parts))


for _cls in (Leaf, LeafProfile, LeafEnd, Interface, Clamp, Clip, Probe, TimeFunction, _core.RigidBody, _core.Loading,
             _core.Mesh, _core.Model, _core.Simulation, _core.Outputs):
    _cls.__repr__ = _fields_repr
for _cls in (_core.LeafList, _core.InterfaceList, _core.ClampList, _core.ClipList):
    _cls.__repr__ = lambda items: "[%s]" % ", ".join(repr(x) for x in items)
Scenario.__repr__ = lambda s: "<stackbeam.Scenario %s: %d leaves, mode %s, t_end_s %g>" % (
    s.source, len(s.model.leaves), s.simulation.mode, s.simulation.t_end_s)


def _input_error(field, message, kind=InputError):
    """An InputError (or InputTypeError) raised from Python, as the C++ ones: ``field`` the name
    given, ``location`` empty."""
    error = kind("%s: %s" % (field, message))
    error.field = field
    error.location = ""
    return error


def _check_bool(name, value):
    if not isinstance(value, bool):
        raise _input_error(name, "value %r is not allowed: must be True or False" % (value,), InputTypeError)


def _check_path(name, value):
    if not isinstance(value, (str, _os.PathLike)):
        raise _input_error(name, "value %r is not allowed: must be a path (a str or an os.PathLike)" % (value,),
                           InputTypeError)
    return _os.fspath(value)


def _flatten_options(options, prefix=""):
    """simulate's keyword options as {member: value}: nested dicts (cvode={"rtol": 1e-9})
    and dotted names ({"cvode.rtol": 1e-9}) alike."""
    flat = {}
    for key, value in options.items():
        if isinstance(value, _Mapping):
            flat.update(_flatten_options(value, prefix + key + "."))
        else:
            flat[prefix + key] = value
    return flat


class _Columns(_Mapping):
    """A mapping from column names to numpy arrays (self._columns), with to_pandas()."""

    def __getitem__(self, name):
        return self._columns[name]

    def __iter__(self):
        return iter(self._columns)

    def __len__(self):
        return len(self._columns)

    def to_pandas(self):
        """The columns as a pandas DataFrame (needs pandas)."""
        try:
            import pandas
        except ImportError as e:  # pragma: no cover - pandas is optional
            raise ImportError("to_pandas needs pandas (Debian: apt-get install python3-pandas)") from e
        return pandas.DataFrame(dict(self._columns))


class Result(_Columns):
    """A run's results: a mapping from the time-series CSV's column names (``t``, ``w``,
    ``spring_force``, ...) to numpy arrays, one entry per record (the first: t = 0).

    Attributes: ``pairs`` (every contact pair at every record, a dict of arrays with the
    --pairs CSV's columns; None unless simulate(..., pairs=True)), ``nodes`` (every leaf's
    nodal displacements at every record, a dict of arrays with the --nodes CSV's columns t,
    leaf, x, w, theta, the half model mirrored to whole leaves; None unless
    simulate(..., nodes=True)), ``stresses`` (every leaf's stresses at every record: a list
    with one dict per leaf of ``leaf``, ``t`` (records), ``x`` (nodes, whole leaf [m]) and
    (records x nodes) arrays ``sigma_top``, ``sigma_bottom`` [Pa, tension positive], ``N`` [N],
    ``M`` [N m], ``V`` [N]; None unless simulate(..., stresses=True), which also puts the run's
    stress figures in ``summary["stresses"]``), ``events`` (the event
    log of mode cvode, the --events CSV's columns; None in the other modes), ``summary``
    (the command line's JSON summary as a dict), ``report`` (the run's counters, and
    ``without_gil_s``: when the run stepped without the GIL, on time.monotonic()'s clock),
    ``scenario`` (a copy of the scenario run) and ``options`` (the options given)."""

    def __init__(self, raw, scenario, options):
        self._columns = raw["columns"]
        self.pairs = raw["pairs"]
        self.nodes = raw["nodes"]
        self.stresses = raw["stresses"]
        self.events = raw["events"]
        self.report = raw["report"]
        self.summary = _json.loads(raw["summary"])
        self.scenario = scenario
        self.options = options

    def __repr__(self):
        n = len(self._columns["t"])
        return "<stackbeam.Result: %d records to t = %g s, columns %s>" % (
            n, self._columns["t"][-1] if n else 0.0, ", ".join(self._columns))


def simulate(scenario, *, pairs=False, nodes=False, stresses=False, **options):
    """Runs `scenario` (a Scenario) from t = 0 to t_end_s and returns a Result.

    ``options``: SimulationOptions members over the scenario's, e.g. ``t_end_s=1.0,
    mode="cvode"``; nested ones as a dict (``cvode={"rtol": 1e-9}``) or dotted
    (``**{"cvode.rtol": 1e-9}``). Each is checked by the option table: InputError naming
    the member. ``pairs=True`` keeps every pair at every record (Result.pairs); ``nodes=True``
    every leaf's nodal displacements at every record (Result.nodes; off by default: a run of
    N records on a mesh of n nodes keeps 5 N n numbers); ``stresses=True`` every leaf's stresses
    at every record (Result.stresses) and the run's stress figures (Result.summary["stresses"]:
    extremes, the cycle's range, fatigue where a leaf has a material, the interfaces' peak
    pressures; in the massless modes a solve per record).

    The GIL is released while the run steps, so runs on Python threads run in parallel;
    Ctrl-C raises KeyboardInterrupt within about 20 ms of the run's next stop check (before every
    record, and every 64 internal steps of mode cvode; the run is dropped)."""
    flat = _flatten_options(options)
    if not isinstance(scenario, Scenario):
        raise _input_error("scenario", "value %r is not allowed: must be a stackbeam.Scenario" % (scenario,), InputTypeError)
    for name, value in (("pairs", pairs), ("nodes", nodes), ("stresses", stresses)):
        if not isinstance(value, bool):
            raise _input_error(name, "value %r is not a bool: give True to keep them, False (the default) not to" % (value,),
                               InputTypeError)
    raw = _core._run(scenario, flat, pairs, nodes, stresses)
    return Result(raw, scenario.copy(), flat)


class SweepResult(_Columns):
    """The points table of a sweep (stackbeam.sweep): a mapping from points.csv's column names
    to numpy arrays, one entry per point in point order: ``point``, one column per axis named
    exactly as its key, ``status`` ("ok", "failed", "input-error"), ``message``, the figures
    (``loop_area_j``, ``dynamic_rate_n_per_m``, ``loss_factor``, ...; NaN where a point has
    no loop) and ``wall_time_s``. ``.axes``: the axis keys; ``.figures``: the figure names."""

    def __init__(self, raw):
        self._columns = raw["columns"]
        self.axes = list(raw["axes"])
        self.figures = list(raw["figures"])
        self.scenario_path = raw["scenario_path"]
        self.wall_time_s = raw["wall_time_s"]
        self.jobs = raw["jobs"]

    def __repr__(self):
        n = len(self._columns["point"])
        ok = int((self._columns["status"] == "ok").sum())
        return "<stackbeam.SweepResult: %d points (%d ok) over %s>" % (n, ok, ", ".join(self.axes))


def sweep(spec, *, jobs=None, out_dir=None, restart=False, keep_series=False):
    """Runs the sweep spec file `spec` (docs/sweep.md) as `stackbeam sweep` does and returns its
    points table (a SweepResult), figure for figure the command line's points.csv.

    ``jobs``: threads (default None: the machine's cores), an int from 1 to MAX_SWEEP_JOBS (1024);
    a thread the system refuses (its thread or memory limit) raises ThreadStartError. Every point's scenario is read and checked
    before any run: a bad spec raises InputError naming the spec file's line, the key and the
    point. ``out_dir``: also keep the results in that directory as the command line does
    (journal, points.csv, sweep.json, loops; ``keep_series`` the records; an interrupted sweep
    is resumed by the same call, ``restart=True`` starts over); without it nothing is written.
    The GIL is released while the points run; Ctrl-C stops the sweep (KeyboardInterrupt)."""
    spec = _check_path("spec", spec)
    out_dir = "" if out_dir is None else _check_path("out_dir", out_dir)
    _check_bool("restart", restart)
    _check_bool("keep_series", keep_series)
    raw = _core._sweep(spec, jobs, out_dir, restart, keep_series)
    return SweepResult(raw)


Stepper = _core.Stepper  # advance(), pairs(), nodes(), report(), current, record_index, records, dt_s
MAX_SWEEP_JOBS = _core.MAX_SWEEP_JOBS


def _stepper_iter(self):
    """Advances to the end of the run, yielding each record."""
    while self.record_index < self.records - 1:
        yield self.advance()


Stepper.__iter__ = _stepper_iter


def make_stepper(scenario, **options):
    """A run of `scenario` one record at a time (co-simulation loops), options as in simulate():
    ``advance()`` returns the next record (a dict of the CSV's columns), ``pairs()`` the contact
    pairs at the current one, ``nodes()`` every leaf's nodes there, ``current`` the current record, ``record_index``, ``records``
    (to t_end_s), ``dt_s``, ``report()``. Iterating over it advances to the end; advance() past
    the last record raises InputError (field "advance"). Ctrl-C inside advance() raises
    KeyboardInterrupt and leaves the stepper at its last record."""
    if not isinstance(scenario, Scenario):
        raise _input_error("scenario", "value %r is not allowed: must be a stackbeam.Scenario" % (scenario,), InputTypeError)
    return Stepper(scenario, _flatten_options(options))


def fit(spec, *, jobs=None):
    """Fits the scenario keys of the fit spec file `spec` (docs/calibration.md) to its measured
    loops, as `stackbeam fit` does, and returns a dict: ``parameters`` (key, value,
    standard_error, identifiable, note, ...), ``correlation``, ``warnings``, ``cost``,
    ``runs``, ``loops`` (name, w_m, measured_force_n, fitted_force_n, branch as numpy arrays;
    the loop areas), ``history`` and ``fitted_scenario`` (TOML text). Writes no file; the GIL
    is released while the runs go on ``jobs`` threads (None: the machine's cores)."""
    return _core._fit(str(spec), jobs)
