"""Figures of a run with matplotlib: the command line's --plot figures (displacement, forces,
friction force at the probe, force-deflection loop), each on an Axes you may give.

    import stackbeam, stackbeam.plot
    result = stackbeam.simulate(stackbeam.load_scenario("scenarios/rig_friction.toml"))
    stackbeam.plot.loop(result)
    stackbeam.plot.save_all(result, "rig")   # rig_displacement.png, rig_force.png, ...

Units on the axes: mm for displacements, N for forces, s for time (the columns are SI).
"""


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


FIGURES = {"displacement": displacement, "force": force, "friction": friction, "loop": loop}


def save_all(result, prefix, dpi=100):
    """Writes PREFIX_displacement.png, PREFIX_force.png, PREFIX_friction.png, PREFIX_loop.png
    (the command line's --plot files) and returns their names."""
    import matplotlib.pyplot as plt

    files = []
    for name, draw in FIGURES.items():
        ax = draw(result)
        files.append("%s_%s.png" % (prefix, name))
        ax.figure.savefig(files[-1], dpi=dpi)
        plt.close(ax.figure)
    return files
