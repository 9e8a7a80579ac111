#!/usr/bin/python3
"""Cost against error of a tradeoff study (Study/Design = tradeoff; docs/tradeoff.md).

    /usr/bin/python3 scripts/tradeoff.py STUDY_OUTPUT_DIR

Reads study_summary.csv (case 0 is the reference, each other row one rung of one
ladder, columns "knob" and "value") and each case's summary.json and profiles.csv.
For every complete case:

- cost: wall time per simulated time, s per simulated microsecond (summary.json
  wall_time / simulated_time), and its ratio to the reference's;
- mu_mean +/- mu_stderr (summary.json results.mu_mean, results.mu_stderr: the
  batch-means standard error) and mu_error = |mu - mu_ref| / mu_ref;
- sigma_yy_mean, sigma_xy_mean +/- their summary.json *_stderr (Pa);
- power_balance_ratio +/- power_balance_ratio_stderr, balance_residual =
  |1 - ratio| of the case itself and balance_residual_over_se = residual / stderr;
- for mu, sigma_yy, sigma_xy and the power balance ratio, X_diff_over_se =
  (X - X_ref) / sqrt(se^2 + se_ref^2): the difference against the reference over the
  combined standard error of the two means (power_balance_diff_over_se for the
  ratio); |X_diff_over_se| > 2 is marked "significant" in tradeoff.md, below it the
  difference is within the statistical noise of two runs;
- vx_l2, sigma_yy_l2, sigma_xy_l2: relative L2 differences of the profiles,
  ||p - p_ref|| / ||p_ref||, with p interpolated at the reference's layer heights y/h;
- steady_state_reached as summary.json gives it.

Writes tradeoff.csv, tradeoff.md and tradeoff.png (cost against the mu error and
against the largest profile error, Pareto fronts drawn; on the mu panel, rungs whose
mu is within 2 combined standard errors of the reference's are open circles); exits 1
if the reference is not complete.

A study of the collision scene (summary.json "scene" = collision) is measured on what
that scene gives instead: cost = wall time of the collision, s; restitution_error =
|e - e_ref| (e = v_out / v_in); energy_loss_error = |loss - loss_ref| (loss = 1 - KE_final
/ KE_initial); duration_error = |t_c - t_c,ref| / t_c,ref (t_c the contact duration);
outcome = whether the discs separated, as the reference did or not. The plot is cost
against the restitution and the duration errors.
"""
import csv
import json
import math
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

PROFILES = ("vx", "sigma_yy", "sigma_xy")
COMPARED_STRESSES = ("sigma_yy", "sigma_xy")  # summary.json *_mean, *_stderr


def read_profiles(path):
    if not os.path.exists(path) or os.path.getsize(path) == 0:
        return None
    p = np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True))
    return p if p.size >= 2 else None


def relative_l2(p, ref, q):
    """||p_q - ref_q|| / ||ref_q|| with p interpolated at ref's y/h."""
    values = np.interp(ref["y_over_h"], p["y_over_h"], p[q])
    norm = np.linalg.norm(ref[q])
    return float(np.linalg.norm(values - ref[q]) / norm) if norm > 0 else float("nan")


def number(x):
    """@p x as a float if it is a finite number (summary.json writes NaN as null), else nan."""
    ok = isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
    return float(x) if ok else float("nan")


def diff_over_se(x, se, x_ref, se_ref):
    """(x - x_ref) / sqrt(se^2 + se_ref^2): a difference in combined standard errors
    (0 for identical means, nan if a standard error is missing)."""
    x, se, x_ref, se_ref = number(x), number(se), number(x_ref), number(se_ref)
    combined = math.sqrt(se * se + se_ref * se_ref)
    if x == x_ref:
        return 0.0
    return (x - x_ref) / combined if combined > 0 else float("nan")


def significant(z):
    return math.isfinite(z) and abs(z) > 2


def pareto(points):
    """Indices of the points (cost, error) that no other point beats in both."""
    front = []
    for i, (c, e) in enumerate(points):
        if not (math.isfinite(c) and math.isfinite(e)):
            continue
        if not any((c2 <= c and e2 <= e) and (c2 < c or e2 < e)
                   for j, (c2, e2) in enumerate(points) if j != i and math.isfinite(c2) and math.isfinite(e2)):
            front.append(i)
    return sorted(front, key=lambda i: points[i][0])


def fmt(v, digits=3):
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.{digits}g}"


def fmt_se(mean, se, digits=4, scale=1.0):
    """"mean +/- stderr" of a summary.json figure (divided by @p scale); "-" without a mean."""
    mean, se = number(mean), number(se)
    if not math.isfinite(mean):
        return "-"
    return f"{mean / scale:.{digits}g} +/- " + (f"{se / scale:.2g}" if math.isfinite(se) else "-")


def fmt_z(z):
    """A difference in combined standard errors, marked "significant" beyond 2."""
    if not math.isfinite(z):
        return "-"
    return f"{z:+.1f}" + (" **significant**" if significant(z) else "")


def tabulate(cases, measure):
    """One row per case: knob, value, status and directory, then measure(case, row) fills
    a complete case's figures, "cost" among them; cost_ratio is cost over case 0's."""
    table = []
    for c in cases:
        s = c["summary"]
        out = {"knob": c["row"]["knob"], "value": c["row"]["value"], "status": s.get("status", "missing"),
               "directory": c["row"]["directory"]}
        if c["complete"]:
            measure(c, out)
        table.append(out)
    for t in table:
        if "cost" in t:
            t["cost_ratio"] = t["cost"] / table[0]["cost"]
    return table


def write_outputs(directory, table, columns, md, panels, ref_cost, cost_label, hlines=(), hollow=None):
    """tradeoff.csv (@p columns of @p table), tradeoff.md (the lines @p md) and tradeoff.png,
    each written atomically. @p panels: (row key or function of a row, y label) per subplot;
    each plots cost against that error for every rung, with the Pareto front and the
    reference's cost; @p hlines: (panel index, y, label) reference lines; @p hollow:
    (panel index, function of a row, legend label): rows it is true for drawn open there."""
    tmp = os.path.join(directory, "tradeoff.csv.tmp")
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        for t in table:
            w.writerow({k: t.get(k, "") for k in columns})
    os.replace(tmp, os.path.join(directory, "tradeoff.csv"))
    with open(os.path.join(directory, "tradeoff.md.tmp"), "w") as f:
        f.write("\n".join(md) + "\n")
    os.replace(os.path.join(directory, "tradeoff.md.tmp"), os.path.join(directory, "tradeoff.md"))

    rungs = [t for t in table if "cost" in t and t["knob"] != "reference"]
    knobs = sorted({t["knob"] for t in rungs})
    colours = {k: f"C{i}" for i, k in enumerate(knobs)}
    fig, axes = plt.subplots(1, len(panels), figsize=(11, 4.5))
    for i, (ax, (key, label)) in enumerate(zip(axes, panels)):
        error = key if callable(key) else (lambda t, key=key: t[key])
        pts = [(t["cost"], error(t), t) for t in rungs]
        pts = [(c, e, t) for c, e, t in pts if math.isfinite(c) and math.isfinite(e) and e > 0]
        for c, e, t in pts:
            open_marker = hollow is not None and hollow[0] == i and hollow[1](t)
            ax.plot(c, e, "o", color=colours[t["knob"]], mfc="none" if open_marker else colours[t["knob"]])
            ax.annotate(t["value"], (c, e), fontsize=7, xytext=(3, 3), textcoords="offset points")
        front = pareto([(c, e) for c, e, _ in pts])
        ax.plot([pts[i][0] for i in front], [pts[i][1] for i in front], "k--", lw=1, label="Pareto front")
        ax.axvline(ref_cost, color="k", lw=1, label="reference cost (its error is 0)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(cost_label)
        ax.set_ylabel(label)
    for i, y, label in hlines:
        axes[i].axhline(y, color="grey", lw=0.8, ls=":", label=label)
    for k in knobs:
        axes[0].plot([], [], "o", color=colours[k], label=k)
    if hollow is not None:
        axes[hollow[0]].plot([], [], "o", color="k", mfc="none", label=hollow[2])
        axes[hollow[0]].legend(fontsize=7)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    tmp = os.path.join(directory, "tradeoff.tmp.png")
    fig.savefig(tmp, dpi=110, bbox_inches="tight")
    plt.close(fig)
    os.replace(tmp, os.path.join(directory, "tradeoff.png"))


def main(directory):
    with open(os.path.join(directory, "study_summary.csv")) as f:
        rows = list(csv.DictReader(f))
    if not rows or "knob" not in rows[0]:
        sys.exit(f"{directory}/study_summary.csv: not a tradeoff study (no 'knob' column)")
    cases = []
    for r in rows:
        d = os.path.join(directory, r["directory"])
        try:
            with open(os.path.join(d, "summary.json")) as f:
                s = json.load(f)
        except (OSError, ValueError):
            s = {"status": "missing"}
        cases.append({"row": r, "dir": d, "summary": s, "complete": s.get("status") == "complete"})
    ref = cases[0]
    if not ref["complete"]:
        sys.exit(f"{directory}: the reference case ({ref['row']['directory']}) is not complete: "
                 f"status {ref['summary'].get('status')}")
    if ref["summary"].get("scene") == "collision":
        return collision_tradeoff(directory, cases)
    ref_results = ref["summary"]["results"]
    ref_profiles = read_profiles(os.path.join(ref["dir"], "profiles.csv"))
    mu_ref = ref_results.get("mu_mean")
    se_ref = number(ref_results.get("mu_stderr"))

    def measure(c, out):
        s = c["summary"]
        res = s["results"]
        out["cost"] = s["wall_time"] / (s["simulated_time"] * 1e6)
        mu = res.get("mu_mean")
        out["mu_mean"] = mu
        out["mu_stderr"] = number(res.get("mu_stderr"))
        out["mu_error"] = abs(mu - mu_ref) / abs(mu_ref) if mu is not None and mu_ref else float("nan")
        out["mu_diff_over_se"] = diff_over_se(mu, res.get("mu_stderr"), mu_ref, se_ref)
        for q in COMPARED_STRESSES:
            out[q + "_mean"] = number(res.get(q + "_mean"))
            out[q + "_stderr"] = number(res.get(q + "_stderr"))
            out[q + "_diff_over_se"] = diff_over_se(res.get(q + "_mean"), res.get(q + "_stderr"),
                                                    ref_results.get(q + "_mean"), ref_results.get(q + "_stderr"))
        prof = read_profiles(os.path.join(c["dir"], "profiles.csv"))
        for q in PROFILES:
            out[q + "_l2"] = (relative_l2(prof, ref_profiles, q)
                              if prof is not None and ref_profiles is not None else float("nan"))
        ratio = res.get("power_balance_ratio")
        ratio_se = number(res.get("power_balance_ratio_stderr"))
        out["power_balance_ratio"] = number(ratio)
        out["power_balance_ratio_stderr"] = ratio_se
        out["balance_residual"] = abs(1 - ratio) if ratio is not None else float("nan")
        out["balance_residual_over_se"] = (out["balance_residual"] / ratio_se
                                           if math.isfinite(ratio_se) and ratio_se > 0 else float("nan"))
        out["power_balance_diff_over_se"] = diff_over_se(ratio, ratio_se, ref_results.get("power_balance_ratio"),
                                                         ref_results.get("power_balance_ratio_stderr"))
        out["solver_iterations_per_step"] = s.get("solver_iterations_mean")
        out["steady_state_reached"] = res.get("steady_state_reached")

    table = tabulate(cases, measure)
    ref_cost = table[0]["cost"]

    columns = ["knob", "value", "status", "cost", "cost_ratio", "mu_mean", "mu_error", "vx_l2",
               "sigma_yy_l2", "sigma_xy_l2", "balance_residual", "solver_iterations_per_step",
               "steady_state_reached", "directory",
               "mu_stderr", "mu_diff_over_se"]
    for q in COMPARED_STRESSES:
        columns += [q + "_mean", q + "_stderr", q + "_diff_over_se"]
    columns += ["power_balance_ratio", "power_balance_ratio_stderr", "power_balance_diff_over_se",
                "balance_residual_over_se"]
    # Two runs as noisy as the reference: 2 combined standard errors, relative to mu_ref.
    noise = 2 * math.sqrt(2) * se_ref / abs(mu_ref) if mu_ref and math.isfinite(se_ref) else float("nan")
    md = [f"Reference: {table[0]['value']}; mean mu {fmt(mu_ref, 4)}, its standard error (batch means) "
          f"{fmt(se_ref, 2)} (summary.json mu_stderr). Each figure is mean +/- standard error; "
          "\"diff / se\" is (rung - reference) / sqrt(se_rung^2 + se_ref^2), **significant** when "
          f"beyond 2 (for a rung as noisy as the reference: mu errors above about {fmt(noise, 2)}).", ""]
    if ref_results.get("steady_state_reached") is not True:
        md += ["**The reference did not reach a steady state** (steady_state_reached false): its means are "
               "over the fallback window; lengthen its run before trusting these differences.", ""]
    md += ["| knob | value | cost (s per simulated us) | cost / reference | mean mu | mu error | mu diff / se | "
           "sigma_yy (MPa) | sigma_yy diff / se | sigma_xy (MPa) | sigma_xy diff / se | power balance ratio | "
           "balance diff / se | balance residual | vx L2 | sigma_yy L2 | sigma_xy L2 | sweeps/step | steady | "
           "status |",
           "|" + "---|" * 20]
    for t in table:
        steady = t.get("steady_state_reached")
        md.append("| " + " | ".join([t["knob"], t["value"], fmt(t.get("cost")), fmt(t.get("cost_ratio")),
                                     fmt_se(t.get("mu_mean"), t.get("mu_stderr")), fmt(t.get("mu_error"), 2),
                                     fmt_z(t.get("mu_diff_over_se", float("nan"))),
                                     fmt_se(t.get("sigma_yy_mean"), t.get("sigma_yy_stderr"), 4, 1e6),
                                     fmt_z(t.get("sigma_yy_diff_over_se", float("nan"))),
                                     fmt_se(t.get("sigma_xy_mean"), t.get("sigma_xy_stderr"), 4, 1e6),
                                     fmt_z(t.get("sigma_xy_diff_over_se", float("nan"))),
                                     fmt_se(t.get("power_balance_ratio"), t.get("power_balance_ratio_stderr"), 3),
                                     fmt_z(t.get("power_balance_diff_over_se", float("nan"))),
                                     fmt(t.get("balance_residual"), 2), fmt(t.get("vx_l2"), 2),
                                     fmt(t.get("sigma_yy_l2"), 2), fmt(t.get("sigma_xy_l2"), 2),
                                     fmt(t.get("solver_iterations_per_step"), 4),
                                     "-" if steady is None else ("yes" if steady else "**no**"),
                                     t["status"]]) + " |")
    hlines = ([(0, noise, "2 combined stderr (rung as noisy as the reference)")] if math.isfinite(noise) else [])
    write_outputs(directory, table, columns, md,
                  [("mu_error", "|mu - mu_ref| / mu_ref"),
                   (lambda t: max(t[q + "_l2"] for q in PROFILES),
                    "largest profile L2 error (vx, sigma_yy, sigma_xy)")],
                  ref_cost, "cost: wall s per simulated us", hlines,
                  (0, lambda t: math.isfinite(t.get("mu_diff_over_se", float("nan"))) and abs(t["mu_diff_over_se"]) <= 2,
                   "within 2 combined stderr of mu_ref"))


def collision_tradeoff(directory, cases):
    """The tradeoff table and plot of a collision study (module docstring)."""
    ref = cases[0]["summary"]["results"]

    def measure(c, out):
        s = c["summary"]
        r = s["results"]
        out["cost"] = s["wall_time"]
        out["steps"] = s.get("steps")
        out["restitution"] = r.get("restitution_coefficient")
        out["energy_loss"] = r.get("energy_loss")
        out["separated"] = r.get("separated")
        out["outcome_as_reference"] = r.get("separated") == ref.get("separated")
        for key, name, relative in (("restitution_coefficient", "restitution_error", False),
                                    ("energy_loss", "energy_loss_error", False),
                                    ("contact_duration", "duration_error", True)):
            a, b = r.get(key), ref.get(key)
            ok = a is not None and b is not None and math.isfinite(a) and math.isfinite(b)
            out[name] = (abs(a - b) / (abs(b) if relative else 1.0)) if ok else float("nan")

    table = tabulate(cases, measure)
    ref_cost = table[0]["cost"]
    columns = ["knob", "value", "status", "cost", "cost_ratio", "steps", "restitution", "restitution_error",
               "energy_loss", "energy_loss_error", "duration_error", "separated", "outcome_as_reference", "directory"]
    md = [f"Reference: {table[0]['value']}; restitution {fmt(ref.get('restitution_coefficient'), 5)}, "
          f"energy loss {fmt(ref.get('energy_loss'), 3)}, separated: {ref.get('separated')}.", "",
          "| knob | value | wall time (s) | cost / reference | steps | restitution | restitution error | "
          "energy loss | energy loss error | duration error | outcome as the reference | status |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for t in table:
        md.append("| " + " | ".join([t["knob"], t["value"], fmt(t.get("cost")), fmt(t.get("cost_ratio")),
                                     str(t.get("steps", "")), fmt(t.get("restitution"), 5),
                                     fmt(t.get("restitution_error"), 2), fmt(t.get("energy_loss"), 3),
                                     fmt(t.get("energy_loss_error"), 2), fmt(t.get("duration_error"), 2),
                                     str(t.get("outcome_as_reference", "")), t["status"]]) + " |")
    write_outputs(directory, table, columns, md,
                  [("restitution_error", "|e - e_ref|"), ("duration_error", "|t_c - t_c,ref| / t_c,ref")],
                  ref_cost, "cost: wall s per collision")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
