#!/usr/bin/python3
"""Energy lost in a cohesive two-disc collision against dt*/dt (Cao et al. 2011, Fig. 8).

Runs `tribo run cases/collision/<law>.prm` for every combination of contact law,
impact velocity and ratio dt*/dt (dt* = sqrt(m_eff/k)), collects each run's
summary.json and writes, in --out:

  collision_study.csv   one row per run (failed runs included, with the reason)
  collision_study.md    the same as a Markdown table, plus the thresholds
  energy_loss.png       log-log energy loss (%) against dt*/dt

With --stiffnesses it also runs the ELAS collision at fixed ratios (--k-ratios)
for several contact stiffnesses k and writes stiffness_study.{csv,md,png}.

Run with Debian's python (numpy, matplotlib):

  /usr/bin/python3 scripts/collision_study.py              # the full study
  /usr/bin/python3 scripts/collision_study.py --quick      # a smoke run

See docs/collision.md for the setup and the results.
"""

import argparse
import concurrent.futures
import csv
import json
import math
import shlex
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

DEFAULT_RATIOS = "1,3,10,30,100,300,1000,3000,10000,30000,100000"
QUICK_RATIOS = "1,100,10000"
QUICK_VELOCITIES = "0.5,2"
LOSS_THRESHOLD = 1e-3  # 0.1 %
PAPER_RATIO, PAPER_VELOCITY = 60000, 2.0

# tribo defaults of the entries the script needs (tribo params).
DEFAULTS = {
    "Simulation/Theta": "0.5",
    "Contact law/Cohesion": "0",
    "Contact law/Cohesion range": "0",
    "Contact law/Stiffness": "1e10",
    "Contact law/Detection distance": "0",
    "Collision/Diameter": "1.2e-6",
    "Collision/Density": "7800",
    "Collision/Initial gap": "1e-10",
}


def parse_prm(path):
    """Entries 'Subsection/Entry' -> value of a deal.II parameter file."""
    values, stack = {}, []
    for raw in Path(path).read_text().splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        words = line.split(None, 1)
        if words[0] == "subsection":
            stack.append(words[1].strip())
        elif words[0] == "end":
            stack.pop()
        elif words[0] == "set" and "=" in words[1]:
            name, value = words[1].split("=", 1)
            values["/".join(stack + [name.strip()])] = value.strip()
    return values


def parse_set(s):
    if "=" not in s:
        raise argparse.ArgumentTypeError(f"--set expects 'Subsection/Entry=value', got '{s}'")
    k, v = s.split("=", 1)
    return k.strip(), v.strip()


def float_list(s):
    try:
        return [float(x) for x in s.split(",") if x.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got '{s}'")


def fmt_num(x):
    """A short, exact-enough label for a number (used in directory names)."""
    return f"{x:g}"


class Physics:
    """Quantities of one collision computed from its resolved parameters."""

    def __init__(self, prm):
        get = lambda k: float(prm.get(k, DEFAULTS[k]))
        self.theta = get("Simulation/Theta")
        self.gamma = get("Contact law/Cohesion")
        self.d_w = get("Contact law/Cohesion range")
        self.k = get("Contact law/Stiffness")
        self.detection = get("Contact law/Detection distance")
        self.diameter = get("Collision/Diameter")
        self.density = get("Collision/Density")
        self.gap = get("Collision/Initial gap")
        radius = 0.5 * self.diameter
        self.m_eff = 0.5 * self.density * math.pi * radius**2
        if self.detection <= 0:  # tribo's default: a tenth of the radius
            self.detection = 0.1 * radius
        self.detection = max(self.detection, self.d_w)
        try:
            self.dt_star = math.sqrt(self.m_eff / self.k)
            self.escape_velocity = math.sqrt(2 * self.gamma * self.d_w / self.m_eff)
        except (ValueError, ZeroDivisionError):
            # Invalid input: let tribo say what is wrong (the run fails, exit code 2).
            self.dt_star = self.escape_velocity = float("nan")

    def model_loss(self, v, ratio):
        """First-order ELAS loss of the Moreau-Jean scheme (docs/collision.md).

        Force on the end-of-step gap: each step of the contact multiplies the
        energy of the linear spring by 1/(1 + theta (h/dt*)^2), i.e. it loses
        theta k h^2 u^2 on average, 2 theta (pi/2) (h/dt*) E per half period.
        With cohesion the spring oscillates about -gamma/k with the energy
        E_osc = m v^2/2 + gamma d_w + gamma^2/(2k) and the contact covers the
        phase pi + 2 delta, sin(delta) = (gamma/k)/A. The switching of the
        cohesion at g = d_w (an error of order gamma v h) is left out.
        """
        m, g, k = self.m_eff, self.gamma, self.k
        if not (m > 0 and k > 0 and ratio > 0 and g >= 0 and self.d_w >= 0):
            return float("nan")
        e0 = 0.5 * m * v * v
        e_osc = e0 + g * self.d_w + g * g / (2 * k)
        amplitude = math.sqrt(2 * e_osc / k)
        delta = math.asin(min(1.0, (g / k) / amplitude))
        arc = math.pi / 2 + delta + 0.5 * math.sin(2 * delta)
        return 2 * self.theta * (e_osc / e0) * arc / ratio


def run_one(job):
    """Run tribo for one job; never raises: failures are returned in the row."""
    row = dict(job["row"])
    cmd = job["cmd"]
    out = Path(job["dir"])
    t0 = time.monotonic()
    try:  # never read a previous run's summary
        (out / "summary.json").unlink()
    except OSError:
        pass
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           timeout=job["timeout"])
        rc, err = p.returncode, (p.stderr or p.stdout).strip()
    except subprocess.TimeoutExpired:
        rc, err = None, f"timed out after {job['timeout']} s"
    except OSError as e:
        rc, err = None, f"cannot run {cmd[0]}: {e}"
    row["wall_time"] = time.monotonic() - t0
    row["exit_code"] = "" if rc is None else rc
    summary = None
    try:
        summary = json.loads((out / "summary.json").read_text())
    except (OSError, ValueError):
        pass
    if summary is not None:
        res = summary.get("results", {})
        row["status"] = summary.get("status", "?")
        row["steps"] = summary.get("steps", "")
        row["tribo_wall_time"] = summary.get("wall_time", "")
        row["time_step"] = summary.get("time_step", row["time_step"])
        for key in ("energy_loss", "restitution_coefficient", "separated", "contact_duration",
                    "escape_velocity", "final_gap"):
            row[key] = res.get(key, "")
        if res.get("contact_duration", "") != "" and res.get("dt_star"):
            row["contact_over_pi_dt_star"] = res["contact_duration"] / (math.pi * res["dt_star"])
        if "error" in summary:
            err = summary["error"]
    else:
        row["status"] = "failed" + ("" if rc is None else f" (exit code {rc})")
    if rc != 0 or row["status"] != "complete":
        row["error"] = " ".join(err.split())[-300:] if err else f"exit code {rc}"
        if row["status"] == "complete":
            row["status"] = "failed"
    return row


def make_jobs(args, laws, velocities, ratios, stiffnesses, tag):
    """One job per (law, velocity, ratio, stiffness)."""
    jobs = []
    for law in laws:
        base = args.cases / f"{law.lower()}.prm"
        if not base.is_file():
            sys.exit(f"error: {base}: no base case for law {law}")
        prm = parse_prm(base)
        prm.update(dict(args.set))
        for k in stiffnesses:
            if k is not None:
                prm["Contact law/Stiffness"] = repr(k)
            phys = Physics(prm)
            for v in velocities:
                for ratio in ratios:
                    h = phys.dt_star / ratio
                    # No contact can be missed if theta*v*h < detection distance
                    # (docs/collision.md): raise the distance to v*h when needed.
                    detection = max(phys.detection, abs(v) * h)
                    # Approach and separation over the detection distance (with
                    # a rebound possibly 10 times slower) plus 20 dt* of contact.
                    end_time = 10 * (phys.gap + detection) / abs(v) + 20 * phys.dt_star
                    if not math.isfinite(end_time) or end_time <= 0:
                        end_time = 1e-6  # invalid input: tribo reports it
                    if not math.isfinite(detection):
                        detection = 1e-9
                    name = f"{law.lower()}_v{fmt_num(v)}_r{fmt_num(ratio)}"
                    if k is not None:
                        name += f"_k{fmt_num(k)}"
                    out = args.out / "runs" / tag / name
                    sets = [f"Collision/Impact velocity={v!r}",
                            f"Collision/Time step ratio={ratio!r}",
                            f"Simulation/End time={end_time:.6g}",
                            f"Contact law/Detection distance={detection:.6g}"]
                    if k is not None:
                        sets.append(f"Contact law/Stiffness={k!r}")
                    sets += [f"{a}={b}" for a, b in args.set]
                    cmd = [str(args.tribo), "run", str(base), "--output", str(out)]
                    for s in sets:
                        cmd += ["--set", s]
                    cmd.append("--quiet")
                    row = {
                        "law": law, "velocity": v, "ratio": ratio, "stiffness": phys.k,
                        "dt_star": phys.dt_star, "time_step": h, "detection_distance": detection,
                        "end_time": end_time, "status": "", "exit_code": "", "energy_loss": "",
                        "model_energy_loss": phys.model_loss(v, ratio) if law == "ELAS" else "",
                        "restitution_coefficient": "", "separated": "", "contact_duration": "",
                        "contact_over_pi_dt_star": "", "escape_velocity": phys.escape_velocity,
                        "final_gap": "", "steps": "", "wall_time": "", "tribo_wall_time": "",
                        "output": str(out), "error": "",
                    }
                    jobs.append({"row": row, "cmd": cmd, "dir": out, "timeout": args.timeout})
    return jobs


def run_jobs(jobs, n_jobs):
    rows = [None] * len(jobs)
    done = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=n_jobs) as pool:
        futures = {pool.submit(run_one, j): i for i, j in enumerate(jobs)}
        for f in concurrent.futures.as_completed(futures):
            i = futures[f]
            rows[i] = f.result()
            done += 1
            r = rows[i]
            loss = r["energy_loss"]
            loss_s = f"{100 * loss:.4g} %" if isinstance(loss, (int, float)) else "-"
            print(f"[{done}/{len(jobs)}] {r['law']} v={r['velocity']:g} ratio={r['ratio']:g}"
                  + (f" k={r['stiffness']:g}" if "_k" in Path(r["output"]).name else "")
                  + f": {r['status']}, loss {loss_s}, {r['wall_time']:.2f} s"
                  + (f" ({r['error']})" if r["error"] else ""), flush=True)
    return rows


def ok(r):
    return r["status"] == "complete" and isinstance(r["energy_loss"], (int, float))


def thresholds(rows):
    """Per (law, velocity): smallest measured ratio with loss < 0.1 %, the
    log-log interpolated crossing, and loss*ratio at the largest ratio."""
    out = []
    keys = sorted({(r["law"], r["velocity"]) for r in rows}, key=lambda t: (t[0] != "ELAS", t))
    for law, v in keys:
        pts = sorted((r["ratio"], r["energy_loss"], r["separated"]) for r in rows
                     if r["law"] == law and r["velocity"] == v and ok(r))
        smallest = next((R for R, L, s in pts if L < LOSS_THRESHOLD and s is True), None)
        crossing = None
        for (r0, l0, _), (r1, l1, s1) in zip(pts, pts[1:]):
            if l0 >= LOSS_THRESHOLD > l1 > 0 and s1 is True:
                a = (math.log(LOSS_THRESHOLD) - math.log(l0)) / (math.log(l1) - math.log(l0))
                crossing = math.exp(math.log(r0) + a * (math.log(r1) - math.log(r0)))
                break
        # loss ~ A / ratio for small steps: A from the largest ratio (if the loss is small).
        constant = pts[-1][0] * pts[-1][1] if pts and pts[-1][1] < 0.1 else None
        out.append({"law": law, "velocity": v, "smallest": smallest, "crossing": crossing,
                    "loss_times_ratio": constant, "largest_ratio": pts[-1][0] if pts else None,
                    "n_ok": len(pts)})
    return out


def write_csv(rows, path):
    fields = list(rows[0].keys())
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for r in rows:
            w.writerow(r)


def g(x, spec=".4g"):
    return format(x, spec) if isinstance(x, (int, float)) and not isinstance(x, bool) else "-"


def markdown_table(rows, with_k=False):
    head = ["law", "v (m/s)"] + (["k (N/m²)"] if with_k else []) + [
        "dt*/dt", "dt (s)", "energy loss (%)", "model (%)", "restitution", "separated",
        "contact / (π dt*)", "steps", "wall (s)"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        if ok(r):
            loss = g(100 * r["energy_loss"]) + ("" if r["separated"] is True else " †")
            sep = "yes" if r["separated"] is True else "**no**"
        elif r["status"] == "complete" and r["separated"] is not True:
            loss = "bound †"  # tribo reports no loss for a pair that did not separate
            sep = "**no**"
        else:
            loss = f"**{r['status'] or 'failed'}**" + (f": {r['error']}" if r["error"] else "")
            sep = "-"
        # The first-order model only holds for small steps (dt*/dt >= 10).
        model = (g(100 * r["model_energy_loss"])
                 if r["model_energy_loss"] != "" and r["ratio"] >= 10 else "-")
        cells = [r["law"], g(r["velocity"])] + ([g(r["stiffness"], ".0e")] if with_k else []) + [
            g(r["ratio"], ".6g"), g(r["time_step"], ".3e"), loss, model,
            g(r["restitution_coefficient"], ".6g"), sep, g(r["contact_over_pi_dt_star"], ".3f"),
            g(r["steps"], "d") if isinstance(r["steps"], int) else "-", g(r["wall_time"], ".2f")]
        lines.append("| " + " | ".join(cells) + " |")
    if any(ok(r) and r["separated"] is not True for r in rows):
        lines += ["", "† Not separated at End time: 1 - KE(End time)/KE(0) is not a collision "
                  "loss. IQS: the discs stick (KE = 0). ELAS: the discs stay bound in the "
                  "cohesive well and oscillate about the overlap γ/k, so the kinetic energy "
                  "at End time depends on the phase and can exceed the initial one (negative "
                  "'loss') when γ²/(2k) is large."]
    return "\n".join(lines)


def threshold_lines(th):
    lines = ["| law | v (m/s) | smallest measured dt*/dt with loss < 0.1 % | "
             "interpolated dt*/dt at 0.1 % | loss × dt*/dt at the largest ratio |",
             "|---|---|---|---|---|"]
    for t in th:
        lines.append(f"| {t['law']} | {t['velocity']:g} | "
                     f"{g(t['smallest'], '.6g') if t['smallest'] else 'none in the measured range'} | "
                     f"{g(t['crossing'], '.0f') if t['crossing'] else '-'} | "
                     f"{g(t['loss_times_ratio'], '.3f')} |")
    return "\n".join(lines)


def colours(n):
    import matplotlib.cm as cm
    return [cm.viridis(x) for x in ([0.0] if n == 1 else [0.85 * i / (n - 1) for i in range(n)])]


def plot_loss(rows, path, phys):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    velocities = sorted({r["velocity"] for r in rows})
    laws = [l for l in ("ELAS", "IQS") if any(r["law"] == l for r in rows)]
    laws += sorted({r["law"] for r in rows} - set(laws))
    col = dict(zip(velocities, colours(len(velocities))))
    fig, ax = plt.subplots(figsize=(9, 6.2))
    style = {"ELAS": ("-", "o"), "IQS": ("--", "s")}
    for law in laws:
        ls, mk = style.get(law, (":", "^"))
        for v in velocities:
            pts = sorted((r["ratio"], 100 * r["energy_loss"], r["separated"]) for r in rows
                         if r["law"] == law and r["velocity"] == v and ok(r))
            if not pts:
                continue
            x = [p[0] for p in pts]
            y = [max(abs(p[1]), 1e-12) for p in pts]
            ax.plot(x, y, ls=ls, marker=mk, ms=5 if law == "ELAS" else 9 - 1.2 * velocities.index(v),
                    color=col[v], mfc=col[v] if law == "ELAS" else "none",
                    label=f"{law}, {v:g} m/s")
            bad = [(p[0], max(abs(p[1]), 1e-12)) for p in pts if p[2] is not True and law != "IQS"]
            neg = [(p[0], abs(p[1])) for p in pts if p[1] < 0]
            if bad:
                ax.plot(*zip(*bad), ls="none", marker="o", ms=13, mfc="none", mec="red", mew=1.5,
                        zorder=5)
            if neg:
                ax.plot(*zip(*neg), ls="none", marker="x", ms=10, color="red", zorder=5)
    x_all = sorted({r["ratio"] for r in rows})
    if x_all and "ELAS" in laws:
        xs = [x_all[0] * (x_all[-1] / x_all[0]) ** (i / 100) for i in range(101)] \
            if x_all[-1] > x_all[0] else x_all
        ax.plot(xs, [min(100.0, 100 * (math.pi / 2) / x) for x in xs], color="grey", ls=":", lw=1.5,
                label="ELAS without cohesion: (π/2)/(dt*/dt)")
    ax.axhline(100 * LOSS_THRESHOLD, color="red", lw=1, ls="-.")
    ax.text(x_all[0] if x_all else 1, 100 * LOSS_THRESHOLD * 1.25, "0.1 %", color="red", va="bottom")
    ax.plot([PAPER_RATIO], [100 * LOSS_THRESHOLD], marker="*", ms=18, color="crimson", ls="none",
            label="Cao et al. 2011: 2 m/s needs\ndt*/dt = 60 000 for < 0.1 %")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("dt* / dt   (dt* = sqrt(m_eff / k))")
    ax.set_ylabel("energy loss in the collision (%)")
    ax.set_title(f"Cohesive collision of two {phys.diameter * 1e6:g} µm discs: "
                 f"γ = {phys.gamma:g} N/m, d_w = {phys.d_w:g} m, k = {phys.k:g} N/m²\n"
                 "IQS: quasi-shock, the discs stick, 100 % lost whatever dt (open squares)",
                 fontsize=10)
    ax.grid(True, which="major", alpha=0.4)
    ax.grid(True, which="minor", alpha=0.12)
    if any(r["separated"] is False for r in rows if ok(r) and r["law"] != "IQS"):
        ax.plot([], [], ls="none", marker="o", ms=11, mfc="none", mec="red",
                label="not separated by End time")
    ax.legend(fontsize=8, ncol=2, loc="lower left")
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def plot_stiffness(rows, path, phys_of_k):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    velocities = sorted({r["velocity"] for r in rows})
    ratios = sorted({r["ratio"] for r in rows})
    col = dict(zip(velocities, colours(len(velocities))))
    marks = ["o", "s", "^", "D", "v"]
    fig, ax = plt.subplots(figsize=(8.5, 5.8))
    for v in velocities:
        for j, R in enumerate(ratios):
            pts = sorted((r["stiffness"], r["energy_loss"] * r["ratio"]) for r in rows
                         if r["velocity"] == v and r["ratio"] == R and ok(r)
                         and r["separated"] is True)
            if pts:
                ax.plot(*zip(*pts), ls="none", marker=marks[j % len(marks)], color=col[v],
                        mfc="none" if j else col[v], ms=7,
                        label=f"measured, {v:g} m/s, dt*/dt = {R:g}")
        ks = sorted({r["stiffness"] for r in rows})
        if ks:
            kk = [ks[0] * (ks[-1] / ks[0]) ** (i / 80) for i in range(81)] if ks[-1] > ks[0] else ks
            ax.plot(kk, [phys_of_k(k).model_loss(v, 1.0) for k in kk], color=col[v], lw=1,
                    label=f"model, {v:g} m/s")
    ax.axhline(math.pi / 2, color="grey", ls=":", label="π/2 (no cohesion)")
    ax.axhline(PAPER_RATIO * LOSS_THRESHOLD, color="crimson", ls="-.",
               label="Cao et al. 2011 at 2 m/s (0.1 % at 60 000)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("contact stiffness k (N/m²)")
    ax.set_ylabel("energy loss × dt*/dt")
    ax.set_title("ELAS: loss × (dt*/dt) against k (loss ∝ dt/dt* at fixed k)", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tribo", type=Path, default=Path("build/bin/tribo"),
                    help="tribo executable (default build/bin/tribo, from the current "
                         "directory or else the repository root)")
    ap.add_argument("--out", type=Path, default=Path("output/collision_study"),
                    help="output directory (default output/collision_study)")
    ap.add_argument("--cases", type=Path, default=ROOT / "cases" / "collision",
                    help="directory of the base cases <law>.prm (default cases/collision)")
    ap.add_argument("--ratios", type=float_list, default=None,
                    help=f"dt*/dt values (default {DEFAULT_RATIOS})")
    ap.add_argument("--velocities", type=float_list, default=None,
                    help="impact velocities, m/s (default 0.5,1,1.5,2)")
    ap.add_argument("--laws", default="ELAS,IQS", help="contact laws (default ELAS,IQS)")
    ap.add_argument("--jobs", type=int, default=2, help="tribo processes at a time (default 2)")
    ap.add_argument("--quick", action="store_true",
                    help=f"smoke run: ratios {QUICK_RATIOS}, velocities {QUICK_VELOCITIES} "
                         "(unless given)")
    ap.add_argument("--stiffnesses", type=float_list, default=None,
                    help="also run the ELAS stiffness study for these k (N/m^2), "
                         "e.g. 1e7,1e8,1e9,1e10,1e11,1e12")
    ap.add_argument("--k-ratios", type=float_list, default=[100.0, 10000.0],
                    help="dt*/dt of the stiffness study (default 100,10000)")
    ap.add_argument("--set", action="append", type=parse_set, default=[],
                    metavar="'Subsection/Entry=value'",
                    help="extra tribo override for every run (repeatable)")
    ap.add_argument("--timeout", type=float, default=600, help="seconds per run (default 600)")
    args = ap.parse_args()

    if args.ratios is None:
        args.ratios = float_list(QUICK_RATIOS if args.quick else DEFAULT_RATIOS)
    if args.velocities is None:
        args.velocities = float_list(QUICK_VELOCITIES if args.quick else "0.5,1,1.5,2")
    laws = [l.strip().upper() for l in args.laws.split(",") if l.strip()]
    if any(r <= 0 for r in args.ratios) or any(v == 0 for v in args.velocities):
        sys.exit("error: ratios must be > 0 and velocities non-zero")
    if not args.tribo.exists() and not args.tribo.is_absolute() and (ROOT / args.tribo).exists():
        args.tribo = ROOT / args.tribo
    if not args.tribo.exists():
        sys.exit(f"error: {args.tribo}: no tribo executable (build it with bash scripts/build)")
    args.tribo = args.tribo.resolve()
    args.out.mkdir(parents=True, exist_ok=True)
    command = "/usr/bin/python3 " + " ".join(shlex.quote(a) for a in sys.argv)

    t_start = time.monotonic()
    jobs = make_jobs(args, laws, args.velocities, args.ratios, [None], "sweep")
    print(f"{len(jobs)} runs, {args.jobs} at a time -> {args.out}", flush=True)
    rows = run_jobs(jobs, args.jobs)
    sweep_wall = time.monotonic() - t_start

    base = parse_prm(args.cases / f"{laws[0].lower()}.prm")
    base.update(dict(args.set))
    phys = Physics(base)
    th = thresholds(rows)
    write_csv(rows, args.out / "collision_study.csv")
    try:
        plot_loss(rows, args.out / "energy_loss.png", phys)
        plot_note = "energy_loss.png"
    except Exception as e:  # a missing matplotlib must not lose the table
        plot_note = f"(no plot: {e})"
        print(f"warning: plot failed: {e}", file=sys.stderr)

    n_failed = sum(1 for r in rows if r["status"] != "complete")
    md = ["# Cohesive two-disc collision: energy loss against dt*/dt",
          "",
          f"Command: `{command}`  ",
          f"tribo: `{args.tribo}`; base cases: `{args.cases}`  ",
          f"Discs {phys.diameter:g} m, density {phys.density:g} kg/m³, m_eff = {phys.m_eff:.4g} kg/m; "
          f"cohesion γ = {phys.gamma:g} N/m over d_w = {phys.d_w:g} m "
          f"(escape velocity {phys.escape_velocity:.3g} m/s); k = {phys.k:g} N/m², "
          f"dt* = {phys.dt_star:.4g} s; θ = {phys.theta:g}; initial gap {phys.gap:g} m.  ",
          f"{len(rows)} runs ({n_failed} not complete), {args.jobs} at a time, "
          f"sweep wall time {sweep_wall:.1f} s. Plot: {plot_note}.",
          "",
          "'model' is the first-order estimate of the ELAS loss (docs/collision.md); "
          "'contact / (π dt*)' counts the steps with a non-zero contact force "
          "(cohesive zone included).",
          "",
          markdown_table(rows),
          "",
          "## dt*/dt needed for less than 0.1 % energy loss",
          "",
          threshold_lines(th),
          "",
          f"Cao et al. (2011): {PAPER_RATIO} at {PAPER_VELOCITY:g} m/s (ELAS, cohesion 1 N).",
          ""]

    print(f"\nsweep: {len(rows)} runs in {sweep_wall:.1f} s wall, {n_failed} not complete")
    print("smallest measured dt*/dt with energy loss < 0.1 %:")
    for t in th:
        s = f"{t['smallest']:g}" if t["smallest"] else "none"
        c = f", interpolated {t['crossing']:.0f}" if t["crossing"] else ""
        print(f"  {t['law']:5s} v = {t['velocity']:g} m/s: {s}{c}"
              + (f"  (loss x ratio = {t['loss_times_ratio']:.3f})" if t["loss_times_ratio"] else ""))

    if args.stiffnesses:
        if "ELAS" not in laws:
            print("warning: the stiffness study needs ELAS in --laws; skipped", file=sys.stderr)
        else:
            t0 = time.monotonic()
            kjobs = make_jobs(args, ["ELAS"], args.velocities, args.k_ratios, args.stiffnesses,
                              "stiffness")
            print(f"\nstiffness study: {len(kjobs)} runs", flush=True)
            krows = run_jobs(kjobs, args.jobs)
            k_wall = time.monotonic() - t0
            write_csv(krows, args.out / "stiffness_study.csv")
            eb = parse_prm(args.cases / "elas.prm")
            eb.update(dict(args.set))

            def phys_of_k(k):
                p = dict(eb)
                p["Contact law/Stiffness"] = repr(k)
                return Physics(p)
            try:
                plot_stiffness(krows, args.out / "stiffness_study.png", phys_of_k)
            except Exception as e:
                print(f"warning: stiffness plot failed: {e}", file=sys.stderr)
            krows_sorted = sorted(krows, key=lambda r: (r["velocity"], r["ratio"], r["stiffness"]))
            kmd = ["# ELAS collision: energy loss against the contact stiffness k", "",
                   f"Command: `{command}`  ",
                   f"{len(krows)} runs in {k_wall:.1f} s wall.", "",
                   markdown_table(krows_sorted, with_k=True), ""]
            (args.out / "stiffness_study.md").write_text("\n".join(kmd))
            md += ["## Stiffness study", "", f"See stiffness_study.md ({len(krows)} runs, "
                   f"{k_wall:.1f} s wall) and stiffness_study.png.", ""]
            print(f"stiffness study: {len(krows)} runs in {k_wall:.1f} s wall")

    (args.out / "collision_study.md").write_text("\n".join(md))
    print(f"\nwrote {args.out}/collision_study.csv, collision_study.md, {plot_note}"
          + (", stiffness_study.*" if args.stiffnesses else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
