"""Figures of a run with matplotlib: the command line's --plot figures (displacement, forces,
friction force at the probe, force-deflection loop), each on an Axes you may give.

    import stackbeam, stackbeam.plot
    result = stackbeam.simulate(stackbeam.load_scenario("scenarios/rig_friction.toml"))
    stackbeam.plot.loop(result)
    stackbeam.plot.save_all(result, "rig")   # rig_displacement.png, rig_force.png, ...

The deformed stack (each leaf's deflected axis, every pair coloured by its state) needs the
nodes and the pairs of the run: simulate(..., nodes=True, pairs=True), then
deformed_stack(result, times=[...]) or animate_stack(result, "run.gif"); coloured by the leaves'
fibre stresses instead: simulate(..., nodes=True, stresses=True), then
deformed_stack(result, color_by="stress").

The stresses along each leaf (top and bottom fibre at chosen times, and the cycle's envelope)
need simulate(..., stresses=True), then stresses(result, times=[...]).

Units on the axes: mm for displacements, N for forces, s for time (the columns are SI).
"""
import math as _math

import numpy as _np


def _axes(ax):
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.figure(figsize=(8, 5)).add_subplot()


def _finish(ax, title, xlabel, ylabel, legend=True):
    ax.set(title=title, xlabel=xlabel, ylabel=ylabel)
    ax.grid(True)
    if legend:
        ax.legend(loc="upper right")
    return ax


def displacement(result, ax=None):
    """w (the deflection of R) and w + y_b (absolute, base excitation) against t [mm]."""
    ax = _axes(ax)
    t, w, yb = result["t"], result["w"], result["base_displacement"]
    ax.plot(t, 1000 * w, lw=2, label="w (deflection)")
    ax.plot(t, 1000 * (w + yb), ls="--", label="w + y_b (absolute)")
    return _finish(ax, "displacement of R", "t [s]", "[mm]")


def force(result, ax=None):
    """The spring force, the external force and m w'' on R against t [N]."""
    ax = _axes(ax)
    t = result["t"]
    ax.plot(t, result["spring_force"], lw=2, label="spring force")
    ax.plot(t, result["external_force"], ls="--", label="external force")
    ax.plot(t, result["force_on_mass"], ls=":", label="m d$^2$w/dt$^2$")
    return _finish(ax, "forces on R", "t [s]", "[N]")


def friction(result, ax=None):
    """The friction force p_t at the probe pair against t [N]."""
    ax = _axes(ax)
    ax.plot(result["t"], result["probe_friction_force"], lw=2, label="p$_t$")
    return _finish(ax, "friction force at the probe pair", "t [s]", "[N]")


def loop(result, ax=None):
    """The force-deflection loop: the spring force against w [mm] (its area is the energy
    dissipated per cycle, Result.summary["hysteresis"])."""
    ax = _axes(ax)
    ax.plot(1000 * result["w"], result["spring_force"], lw=1.5)
    return _finish(ax, "force-deflection loop", "w [mm]", "spring force [N]", legend=False)


def fit_loops(fit_result, ax=None):
    """The measured loops (points) and the fitted ones (lines, each branch on its own) of
    stackbeam.fit's result, against w [mm]."""
    ax = _axes(ax)
    for loop in fit_result["loops"]:
        w = 1000 * _np.asarray(loop["w_m"])
        line = ax.plot(w, loop["measured_force_n"], ".", ms=3, label=f"{loop['name']} measured")[0]
        for b in (1, -1):
            sel = _np.asarray(loop["branch"]) == b
            order = _np.argsort(w[sel])
            ax.plot(w[sel][order], _np.asarray(loop["fitted_force_n"])[sel][order], "-", color=line.get_color(), lw=1,
                    label=f"{loop['name']} fitted" if b == 1 else None)
    return _finish(ax, "measured and fitted loops", "w [mm]", "spring force [N]")


FIGURES = {"displacement": displacement, "force": force, "friction": friction, "loop": loop}


def save_all(result, prefix, dpi=100):
    """Writes PREFIX_displacement.png, PREFIX_force.png, PREFIX_friction.png, PREFIX_loop.png
    and, when the result has the nodes (simulate(..., nodes=True)), PREFIX_stack.png (the
    deformed stack at the extreme deflections): the command line's --plot files. Returns their
    names."""
    import matplotlib.pyplot as plt

    files = []
    for name, draw in FIGURES.items():
        ax = draw(result)
        files.append("%s_%s.png" % (prefix, name))
        ax.figure.savefig(files[-1], dpi=dpi)
        plt.close(ax.figure)
    if getattr(result, "nodes", None) is not None:
        fig = deformed_stack(result)
        files.append("%s_stack.png" % prefix)
        fig.savefig(files[-1], dpi=dpi)
        plt.close(fig)
    return files


# ---- the deformed stack -------------------------------------------------------------------

STATE_COLOURS = {"stick": "#1a9850", "slip": "#d73027", "open": "#4575b4"}


def _error(field, message):
    from . import _input_error

    return _input_error(field, message)


def stack_scale(stack_height_m, max_abs_w_m):
    """The deflection's scale of the deformed stack when none is given: the number 1, 2 or 5
    times a power of ten at or below 2 H / max |w| (H the stack's height at the seat, max |w|
    the largest nodal deflection drawn), so that the drawn deflection is up to twice the stack's
    height; the command line's --plot takes the same rule."""
    if not max_abs_w_m > 0.0:
        return 1.0
    target = 2.0 * stack_height_m / max_abs_w_m
    decade = 10.0 ** _math.floor(_math.log10(target))
    for m in (5.0, 2.0, 1.0):
        if m * decade <= target * (1.0 + 1e-12):
            return m * decade
    return decade


class _Stack:
    """The nodes and pairs of a run by record, and the stack's geometry (the drawing's data)."""

    def __init__(self, result):
        if getattr(result, "nodes", None) is None:
            raise _error("nodes", "the result has no nodes: run simulate(..., nodes=True) (and pairs=True for the "
                                  "pairs' states)")
        from . import _core

        geometry = _core._stack_geometry(result.scenario)
        self.heights = _np.asarray(geometry["axis_height_m"])
        self.stack_height = geometry["stack_height_m"]
        self.seat_x = geometry["seat_x_m"]
        self.half = geometry["half"]
        self.x_tolerance = geometry["x_tolerance_m"]
        self.times = _np.asarray(result["t"])
        self.w_record = _np.asarray(result["w"])
        self.seat_rotation = _np.asarray(result["seat_rotation"])  # theta_R [rad], counter-clockwise
        summary = getattr(result, "summary", None) or {}
        self.windup = summary.get("windup") is not None  # the loading turns or pushes the seat
        nodes = result.nodes
        self._node_t, self._leaf = nodes["t"], nodes["leaf"]
        self._x, self._w = nodes["x"], nodes["w"]
        self.pairs = result.pairs
        self.leaves = sorted(set(int(leaf) for leaf in self._leaf))

    def record(self, t_s):
        """Index of the record nearest to t_s; InputError outside the run."""
        t = float(t_s)
        if not (self.times[0] - 1e-12 <= t <= self.times[-1] + 1e-12):
            raise _error("times", "value %g s is outside the run (0 to %g s)" % (t, self.times[-1]))
        return int(_np.argmin(_np.abs(self.times - t)))

    def leaf_axes(self, i):
        """{leaf: (x [m], w [m])} at record i."""
        at = self._node_t == self.times[i]
        return {leaf: (self._x[at & (self._leaf == leaf)], self._w[at & (self._leaf == leaf)]) for leaf in self.leaves}

    def extreme_records(self):
        """The records of the largest and the smallest w, or of theta_R where the loading loads the
        seat (a windup run: the S shapes wound either way)."""
        v = self.seat_rotation if self.windup else self.w_record
        return [int(_np.argmax(v)), int(_np.argmin(v))]

    def max_abs_w(self, records):
        at = _np.isin(self._node_t, self.times[records])
        return float(_np.max(_np.abs(self._w[at]))) if at.any() else 0.0

    def pair_points(self, i, axes, scale):
        """[(x [m], y [m], state)] of the pairs at record i: midway between the drawn axes of the
        interface's two leaves, the half model's pairs mirrored about the seat."""
        if self.pairs is None:
            return []
        at = _np.nonzero(self.pairs["t"] == self.times[i])[0]
        points = []
        for k in at:
            upper = int(self.pairs["interface"][k])
            lower = upper + 1
            if upper not in axes or lower not in axes:
                continue
            x0 = float(self.pairs["x"][k])
            xs = [x0]
            if self.half and abs(x0 - self.seat_x) > self.x_tolerance:
                xs.append(2.0 * self.seat_x - x0)
            for x in xs:
                y = 0.5 * sum(self.heights[leaf] + scale * _np.interp(x, *axes[leaf]) for leaf in (upper, lower))
                points.append((x, y, str(self.pairs["state"][k])))
        return points


def _draw_seat(ax, stack, i, axes, scale):
    """The seat at record i: on every leaf with a node at the seat, a short segment through its drawn
    axis there, of the drawn slope scale x theta_R (the record's seat_rotation: the tied leaves turn
    with it), so that the windup's turn of the seat shows; one Line2D of gid "seat". Returns it."""
    theta = float(stack.seat_rotation[i])
    span = max(float(_np.max(x)) - float(_np.min(x)) for x, _ in axes.values())
    half = 0.06 * span  # [m] along x each side of the seat
    xs, ys = [], []
    for leaf, (x, w) in axes.items():
        at = _np.nonzero(_np.abs(x - stack.seat_x) <= stack.x_tolerance)[0]
        if len(at) == 0:
            continue
        y = stack.heights[leaf] + scale * float(w[at[0]])
        xs += [stack.seat_x - half, stack.seat_x + half, _np.nan]
        ys += [y - scale * theta * half, y + scale * theta * half, _np.nan]
    (line,) = ax.plot(1000 * _np.asarray(xs), 1000 * _np.asarray(ys), color="tab:orange", lw=3.0, alpha=0.8, zorder=4,
                      label="seat, theta_R %.4g mrad" % (1000 * theta))
    line.set_gid("seat")
    return line


def _draw_stack(ax, stack, i, scale):
    """Draws record i of `stack` on ax; returns the artists."""
    axes = stack.leaf_axes(i)
    artists = []
    for leaf, (x, w) in axes.items():
        artists += ax.plot(1000 * x, 1000 * (stack.heights[leaf] + scale * w), color="black", lw=1.8)
    if stack.windup:
        artists.append(_draw_seat(ax, stack, i, axes, scale))
    points = stack.pair_points(i, axes, scale)
    for state, colour in STATE_COLOURS.items():
        chosen = [(x, y) for x, y, s in points if s == state]
        if chosen:
            xy = 1000 * _np.asarray(chosen)
            artists.append(ax.scatter(xy[:, 0], xy[:, 1], s=14, color=colour, label=state, zorder=3,
                                      facecolors="none" if state == "open" else colour))
    return artists


STACK_COLORS = ("state", "stress")
STRESS_CMAP = "coolwarm"  # blue compression, red tension; the scale symmetric about 0


def _draw_stress_stack(ax, stack, i, scale, leaves, norm):
    """Draws record i with each leaf as a band from its bottom to its top fibre (the drawn axis
    -+ half the local thickness: the thickness true, the deflection scaled) coloured by its stress
    [MPa] at that record (result.stresses), Gouraud-shaded: linear through the thickness between
    the two fibres' values, as sigma = N/A - M y/I is, and linear along x between the nodes.
    Returns the meshes, one per leaf, each with gid "leaf L" and its colour data (get_array) the
    (2 x nodes) array [sigma_bottom, sigma_top] at that record [MPa]."""
    axes = stack.leaf_axes(i)
    artists = []
    for s in leaves:
        leaf = int(s["leaf"])
        x_axis, w_axis = axes[leaf]
        x = _np.asarray(s["x"])
        y_axis = stack.heights[leaf] + scale * _np.interp(x, x_axis, w_axis)
        half = 0.5 * _np.asarray(s["thickness"])
        xx = 1000 * _np.vstack([x, x])
        yy = 1000 * _np.vstack([y_axis - half, y_axis + half])
        sigma = _np.vstack([_np.asarray(s["sigma_bottom"])[i], _np.asarray(s["sigma_top"])[i]]) / 1e6
        mesh = ax.pcolormesh(xx, yy, sigma, shading="gouraud", cmap=STRESS_CMAP, norm=norm)
        mesh.set_gid("leaf %d" % leaf)
        artists.append(mesh)
    return artists


def deformed_stack(result, times=None, scale=None, ax=None, color_by="state"):
    """The deformed stack at the records nearest to `times` [s] (default: the records of the
    largest and the smallest w, or of the seat's rotation theta_R where the loading loads the seat
    (a windup run, result.summary["windup"]), as the command line's --plot; there the seat is
    drawn too: a short segment of the drawn slope scale x theta_R on each leaf at the seat, the
    S shape's turn): each leaf's axis at its height in
    the stack plus its deflection times `scale` (default: stack_scale's rule; the scale is printed
    on the figure), every pair a point midway between its two leaves coloured by its state
    (stick green, slip red, open hollow blue), the half model mirrored to the whole stack.
    Needs simulate(..., nodes=True) (and pairs=True for the states). One Axes per time, stacked;
    `ax` (one time only) draws on that Axes. Returns the Figure.

    color_by="stress" (needs simulate(..., nodes=True, stresses=True)): instead of the pairs, each
    leaf drawn as a band of its true local thickness about its drawn axis, coloured by its stress
    at that record [MPa, tension positive]: the top and bottom fibres' (result.stresses' sigma_top,
    sigma_bottom) at the band's edges, linear between them (through the thickness, as the bending
    stress is) and between the nodes; one colour scale symmetric about 0 over every time drawn,
    with a colour bar."""
    if color_by not in STACK_COLORS:
        raise _error("color_by", "value %r is not allowed: must be one of %s" % (color_by, ", ".join(STACK_COLORS)))
    leaves = None
    if color_by == "stress":
        leaves = getattr(result, "stresses", None)
        if leaves is None:
            raise _error("result.stresses", "is None: color_by='stress' needs simulate(..., nodes=True, stresses=True)")
    stack = _Stack(result)
    if times is None:
        records = stack.extreme_records()
    else:
        records = [stack.record(t) for t in _np.atleast_1d(times)]
    if not records:
        raise _error("times", "is empty: give at least one time")
    if scale is None:
        scale = stack_scale(stack.stack_height, stack.max_abs_w(records))
    elif not (isinstance(scale, (int, float)) and _math.isfinite(scale) and scale > 0):
        raise _error("scale", "value %r is not allowed: must be a number > 0 (the drawn deflection per deflection)"
                     % (scale,))
    if ax is not None and len(records) != 1:
        raise _error("ax", "is given with %d times: give one time per Axes" % len(records))
    import matplotlib.pyplot as plt

    if ax is None:
        fig, axs = plt.subplots(len(records), 1, figsize=(9, 3.2 * len(records)), squeeze=False)
        axs = axs[:, 0]
    else:
        fig, axs = ax.figure, [ax]
    norm = None
    if leaves is not None:
        from matplotlib.colors import Normalize

        # the records of the stresses are the run's (Result.stresses' t is result["t"])
        peak = max(float(_np.max(_np.abs(_np.concatenate([_np.asarray(s["sigma_top"])[records],
                                                           _np.asarray(s["sigma_bottom"])[records]])))) for s in leaves)
        peak = peak / 1e6 if peak > 0 else 1.0
        norm = Normalize(-peak, peak)
    for a, i in zip(axs, records):
        if leaves is None:
            _draw_stack(a, stack, i, scale)
        else:
            drawn = _draw_stress_stack(a, stack, i, scale, leaves, norm)
            fig.colorbar(drawn[0], ax=a, label="fibre stress [MPa], tension positive")
        title = "t = %.4g s, w = %.4g mm" % (stack.times[i], 1000 * stack.w_record[i])
        if stack.windup:
            title += ", theta_R = %.4g mrad" % (1000 * stack.seat_rotation[i])
        a.set(title=title, xlabel="x [mm]", ylabel="height + %g x deflection [mm]" % scale)
        a.grid(True)
        if leaves is None and (stack.pairs is not None or stack.windup):
            a.legend(loc="upper right", fontsize="small")
    fig.suptitle("deformed stack: deflection drawn x %g" % scale)
    fig.tight_layout()
    return fig


def animate_stack(result, path, scale=None, fps=25, every=1, dpi=80):
    """An animation of the deformed stack over the run (deformed_stack's drawing at every
    `every`-th record, one scale for the whole run, printed on it) written to `path`: a .gif with
    Pillow (Debian python3-pil) or an .mp4 with ffmpeg (where it is installed). Needs
    simulate(..., nodes=True) (and pairs=True for the states). Returns path."""
    import os

    from matplotlib import animation
    import matplotlib.pyplot as plt

    stack = _Stack(result)
    path = os.fspath(path)
    kind = os.path.splitext(path)[1].lower()
    if kind == ".gif":
        try:
            import PIL  # noqa: F401  (Pillow, matplotlib's GIF writer)
        except ImportError as e:  # pragma: no cover - Debian's matplotlib depends on it
            raise ImportError("a GIF needs Pillow (Debian: apt-get install python3-pil)") from e
        writer = animation.PillowWriter(fps=fps)
    elif kind == ".mp4":
        if not animation.FFMpegWriter.isAvailable():
            raise _error("path", "value '%s': an MP4 needs ffmpeg, which is not installed (apt-get install ffmpeg), "
                                 "or write a .gif" % path)
        writer = animation.FFMpegWriter(fps=fps)
    else:
        raise _error("path", "value '%s' has neither the extension .gif nor .mp4" % path)
    if not (isinstance(every, int) and every >= 1):
        raise _error("every", "value %r is not allowed: must be an integer >= 1" % (every,))
    records = list(range(0, len(stack.times), every))
    if scale is None:
        scale = stack_scale(stack.stack_height, stack.max_abs_w(records))
    elif not (isinstance(scale, (int, float)) and _math.isfinite(scale) and scale > 0):
        raise _error("scale", "value %r is not allowed: must be a number > 0" % (scale,))
    fig, ax = plt.subplots(figsize=(9, 3.5))
    # fixed limits over the run: every frame's drawing on one frame of reference
    lo, hi = _math.inf, -_math.inf
    for i in records:
        for leaf, (x, w) in stack.leaf_axes(i).items():
            y = 1000 * (stack.heights[leaf] + scale * w)
            lo, hi = min(lo, y.min()), max(hi, y.max())
    pad = 0.05 * (hi - lo) + 1.0

    def frame(k):
        ax.clear()
        i = records[k]
        _draw_stack(ax, stack, i, scale)
        ax.set(ylim=(lo - pad, hi + pad), title="t = %.4g s, w = %.4g mm  (deflection drawn x %g)"
               % (stack.times[i], 1000 * stack.w_record[i], scale), xlabel="x [mm]", ylabel="[mm]")
        ax.grid(True)
        if stack.pairs is not None:
            ax.legend(loc="upper right", fontsize="small")
        return []

    anim = animation.FuncAnimation(fig, frame, frames=len(records), blit=False)
    anim.save(path, writer=writer, dpi=dpi)
    plt.close(fig)
    return path


def stresses(result, times=None, ax=None):
    """The fibre stresses along each leaf [MPa, tension positive] at the records nearest to
    `times` [s] (default: the last record), top fibre solid and bottom dashed, over the envelope
    (the least and the greatest stress of either fibre at each node) over the cycle of
    Result.summary["stresses"] (the loading's last period, else the whole run), shaded. One
    Axes per leaf, stacked; `ax` (a one-leaf stack only) draws on that Axes. Needs
    simulate(..., stresses=True). Returns the Figure."""
    leaves = getattr(result, "stresses", None)
    if leaves is None:
        raise _error("result.stresses", "is None: run simulate(..., stresses=True)")
    t = leaves[0]["t"]
    if times is None:
        records = [len(t) - 1]
    else:
        records = [int(_np.argmin(_np.abs(t - float(ti)))) for ti in _np.atleast_1d(times)]
    if not records:
        raise _error("times", "is empty: give at least one time")
    if ax is not None and len(leaves) != 1:
        raise _error("ax", "is given with %d leaves: give one leaf per Axes" % len(leaves))
    cycle = result.summary["stresses"]["cycle"]
    in_cycle = (t >= cycle["t_start_s"] - 1e-9 * max(1.0, abs(cycle["t_end_s"]))) & (t <= cycle["t_end_s"] + 1e-9 * max(1.0, abs(cycle["t_end_s"])))
    import matplotlib.pyplot as plt

    if ax is None:
        fig, axs = plt.subplots(len(leaves), 1, figsize=(9, 2.8 * len(leaves)), squeeze=False, sharex=True)
        axs = axs[:, 0]
    else:
        fig, axs = ax.figure, [ax]
    for a, leaf in zip(axs, leaves):
        x_mm = 1000 * leaf["x"]
        both = _np.concatenate([leaf["sigma_top"][in_cycle], leaf["sigma_bottom"][in_cycle]])
        if len(both):
            a.fill_between(x_mm, both.min(axis=0) / 1e6, both.max(axis=0) / 1e6, color="0.85", label="cycle envelope")
        for i in records:
            line, = a.plot(x_mm, leaf["sigma_top"][i] / 1e6, lw=1.5, label="top, t = %.4g s" % t[i])
            a.plot(x_mm, leaf["sigma_bottom"][i] / 1e6, lw=1.5, ls="--", color=line.get_color(),
                   label="bottom, t = %.4g s" % t[i])
        _finish(a, "leaf %d" % leaf["leaf"], "x [mm]", "fibre stress [MPa]")
    fig.tight_layout()
    return fig
