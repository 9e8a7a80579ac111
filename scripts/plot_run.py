#!/usr/bin/python3
"""PNG plots of one shear-cell run directory (Debian's numpy and matplotlib).

    /usr/bin/python3 scripts/plot_run.py OUTPUT_DIR

Writes, each atomically:

- OUTPUT_DIR/mu.png: the friction coefficient against time, its running mean, and the
  averaging window of summary.json exactly as summary.json reports it (see
  averaging_window): shaded green "steady state (averaged)" when
  results.steady_state_reached is true, orange "averaged window, NOT steady" when it is
  false; over that window the mean results.mu_mean (dashed) and a band of
  +/- 2 results.mu_stderr (batch-means standard error; no band without it);
- OUTPUT_DIR/power.png: powers of the lower wall, upper wall and dissipation, running
  means;
- OUTPUT_DIR/profiles.png: one panel per profile column of profiles.csv against y/h
  (vx, solid fraction, sigma_xx, sigma_yy, sigma_xy with sigma_yx on its panel, then any
  other column that has a *_stderr partner), each with error bars of +/- 2 of its
  *_stderr column where profiles.csv has one.
"""
import json
import math
import os
import sys

from plotting import plt, save  # noqa: E402  (scripts/plotting.py)
import numpy as np  # noqa: E402

# Profile panels: (column, scale, axis label), in this order when present; a column drawn
# on another's panel (sigma_yx on sigma_xy's); columns never given a panel of their own.
PROFILE_PANELS = [("vx", 1.0, "vx (m/s)"), ("solid_fraction", 1.0, "solid fraction"),
                  ("sigma_xx", 1e6, "sigma_xx (MPa)"), ("sigma_yy", 1e6, "sigma_yy (MPa)"),
                  ("sigma_xy", 1e6, "sigma_xy (MPa)")]
PROFILE_OVERLAYS = {"sigma_xy": "sigma_yx"}
PROFILE_NO_PANEL = {"layer", "y", "y_over_h", "n_samples", "n_discs", "sigma_yx"}


def running_mean(v, n):
    n = max(1, min(n, len(v)))
    return np.convolve(v, np.ones(n) / n, mode="same")


def finite(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def averaging_window(results):
    """The window over which summary.json averaged mu, as summary.json says it:
    (start in s, steady, label), or None if it gives no mean mu (a run that did not slide).

    start is results.averaging_start; steady is true only if results.steady_state_reached
    is true (missing counts as false): only then is the window called a steady state."""
    if not finite(results.get("mu_mean")) or not finite(results.get("averaging_start")):
        return None
    steady = results.get("steady_state_reached") is True
    label = "steady state (averaged)" if steady else "averaged window, NOT steady"
    return results["averaging_start"], steady, label


def plot_mu(directory, stats, results):
    t_us = stats["time"] * 1e6
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(t_us, stats["mu"], lw=0.5, color="0.6", label="mu(t)")
    ax.plot(t_us, running_mean(stats["mu"], len(t_us) // 50), color="C0", label="running mean")
    window = averaging_window(results)
    if window is not None:
        start, steady, label = window
        t0, t1 = start * 1e6, t_us[-1]
        ax.axvspan(t0, t1, color="C2" if steady else "C1", alpha=0.12 if steady else 0.2, label=label)
        mean, se = results["mu_mean"], results.get("mu_stderr")
        if finite(se):
            ax.fill_between([t0, t1], mean - 2 * se, mean + 2 * se, color="C3", alpha=0.3, lw=0,
                            label="mean +/- 2 stderr")
            mean_label = f"mean {mean:.4f} +/- {se:.4f} (stderr)"
        else:
            mean_label = f"mean {mean:.4f} (no stderr)"
        ax.plot([t0, t1], [mean, mean], color="C3", ls="--", lw=1.2, label=mean_label)
        if not steady:
            ax.set_title("steady-state rule not met: the mean is over the fallback window, not a steady state",
                         fontsize=8, color="C1")
    ax.set_xlabel("time (us)")
    ax.set_ylabel("friction coefficient mu")
    ax.legend(fontsize=7)
    save(fig, os.path.join(directory, "mu.png"))


def plot_power(directory, stats, results):
    t_us = stats["time"] * 1e6
    fig, ax = plt.subplots(figsize=(7, 3.5))
    n = len(t_us) // 50
    for name, label in (("power_lower_wall", "lower wall (given)"), ("power_upper_wall", "upper wall"),
                        ("power_dissipated", "dissipated in contacts")):
        ax.plot(t_us, running_mean(stats[name], n), label=label)
    ax.set_xlabel("time (us)")
    ax.set_ylabel("power (W/m), running mean")
    ratio, window = results.get("power_balance_ratio"), averaging_window(results)
    if finite(ratio):
        where = window[2] if window is not None else "averaged window"
        se = results.get("power_balance_ratio_stderr")
        text = f"{ratio:.3f} +/- {se:.3f} (stderr)" if finite(se) else f"{ratio:.3f}"
        ax.set_title(f"dissipated / given by the lower wall over the {where}: {text}", fontsize=9)
    ax.legend(fontsize=8)
    save(fig, os.path.join(directory, "power.png"))


def profile_panels(names):
    """(column, scale, label) of each panel of profiles.png for the columns @p names."""
    panels = [c for c in PROFILE_PANELS if c[0] in names]
    known = {c[0] for c in PROFILE_PANELS}
    for name in names:
        if name in known or name in PROFILE_NO_PANEL or name.endswith("_stderr"):
            continue
        if name + "_stderr" in names:
            stress = name.startswith("sigma_")
            panels.append((name, 1e6 if stress else 1.0, f"{name} (MPa)" if stress else name))
    return panels


def plot_profiles(directory):
    path = os.path.join(directory, "profiles.csv")
    if not os.path.exists(path) or os.path.getsize(path) == 0:
        return
    p = np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True))
    if p.size < 2 or p.dtype.names is None or "y_over_h" not in p.dtype.names:
        return
    names = p.dtype.names
    panels = profile_panels(names)
    if not panels:
        return
    fig, axes = plt.subplots(1, len(panels), figsize=(2.6 * len(panels) + 0.8, 3.8), sharey=True, squeeze=False)
    axes = axes[0]
    y = p["y_over_h"]

    def draw(a, name, scale, marker, label=None, **style):
        # Error bars: +/- 2 batch-means standard errors of each layer's mean (profiles.csv).
        err = None
        if name + "_stderr" in names:
            se = p[name + "_stderr"] / scale
            err = np.where(np.isfinite(se), 2 * np.abs(se), 0.0)
        a.errorbar(p[name] / scale, y, xerr=err, fmt=marker, capsize=2, label=label,
                   **{"ms": 3, **style})

    for a, (name, scale, label) in zip(axes, panels):
        overlay = PROFILE_OVERLAYS.get(name)
        if overlay in names:
            draw(a, name, scale, "o-", name)
            draw(a, overlay, scale, "s--", overlay, mfc="none", ms=5)
            a.legend(fontsize=7)
            label = label.replace(name, f"{name}, {overlay}")
        else:
            draw(a, name, scale, "o-")
        a.set_xlabel(label)
        a.grid(alpha=0.3)
    axes[0].set_ylabel("y / h (lower wall 0, upper wall 1)")
    n = int(p["n_samples"][0]) if "n_samples" in names and np.isfinite(p["n_samples"][0]) else None
    fig.suptitle("error bars: +/- 2 standard errors (batch means)"
                 + (f", {n} samples" if n is not None else ""), fontsize=9)
    save(fig, os.path.join(directory, "profiles.png"))


def main(directory):
    stats = np.atleast_1d(np.genfromtxt(os.path.join(directory, "statistics.csv"), delimiter=",", names=True))
    with open(os.path.join(directory, "summary.json")) as f:
        summary = json.load(f)
    results = summary.get("results", {})
    plot_mu(directory, stats, results)
    plot_power(directory, stats, results)
    plot_profiles(directory)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: plot_run.py OUTPUT_DIR")
    main(sys.argv[1])
