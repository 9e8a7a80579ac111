#!/usr/bin/python3
"""A model of one sweep of the contact solve across P ranks in horizontal bands
(dem/parallel/, docs/scaling.md), built from the per-rank counts and calibrated by the
measurements of bench/bench_distributed.cc on this machine.

    /usr/bin/python3 scripts/scaling_model.py

Per sweep, on the busiest rank (an interior band: two neighbours):
    T_P = t_c c N / P                                compute: c contacts per grain, t_c s each
        + 2 (2 alpha + 24 g w / beta)                ghost-to-owner and owner-to-ghost: one message
                                                     per neighbour and phase, 3 doubles per ghost,
                                                     g ghosts per grain of width per boundary side
        + 2 ceil(log2 P) alpha (1 + 2 / k)           the walls' sum every sweep, the stopping test's
                                                     two sums every k sweeps (recursive doubling)
with w = N / H grains across the period for a layer H grains thick. The sweep's efficiency is
E = T_1 / (P T_P); the solve's is E divided by sweeps(P) / sweeps(1), measured only up to four
ranks (1.011-1.017 on two, 1.026 on four). A band must be at least two grains high (a contact
then joins two neighbouring bands at most): P <= H / 2.

A step (docs/scaling.md, "The state split"): the sweeps' share of the one-core step
split as above, and a fraction f of it done whole on every rank (the passes over every body and
disc: predicting them, their centres, motions and heights):
    E_step = 1 / ((1 - f) / E + f P).
Each rank updates only its own grains, and the ghosts' forces and states cross the band
boundaries once a step (the sweeps' exchange, once instead of some sixty times: left out).
It leaves out what the measured two ranks add beyond the sweep model (waiting for the slower
rank, each rank's set-up of its share): it gives 0.99 for two ranks here at 16 000 and 64 000
grains, where they measure 0.78.
"""
import math

# Calibration (bench/bench_distributed.cc, 2026-11-29, idle machine, two ranks bound to cores)
T_CONTACT = {16_000: 0.87e-3 / 33_036, 64_000: 3.76e-3 / 132_057}  # s per contact update, one core
CONTACTS_PER_GRAIN = 132_057 / 64_000
GHOSTS_PER_WIDTH = 278 / (4 * 83)  # ghosts (both sides of one boundary) per grain of width, 16 000 grains
CHECK_INTERVAL = 10
HERE = ("this machine (ping-pong, shared memory)", 0.49e-6, 5.5e9)
NETWORKS = [HERE, ("InfiniBand HDR (typical)", 1.5e-6, 12e9), ("10 Gb Ethernet (typical)", 20e-6, 1.1e9)]
MEASURED_T2 = {16_000: 0.449e-3, 64_000: 2.05e-3}  # s per sweep on two ranks (warm, 1e-3)
# A step at 64 000 grains, APGS 1e-3 (docs/scaling.md, "Whole runs"): one core 376 ms, and the
# passes every rank made over every body and disc (instrumented once on two ranks: predicting
# the bodies 1.3 ms, the discs' centres and motions 1.6, their heights 0.8, keeping the
# ownership for a retake 0.2), an upper bound since those passes take only the held bodies.
WHOLE_FRACTION = 3.9e-3 / 0.376


def sweep_time(n, p, thickness, alpha, beta, t_c):
    width = n / thickness
    boundaries = 0 if p == 1 else (1 if p == 2 else 2)
    compute = t_c * CONTACTS_PER_GRAIN * n / p
    ghosts = GHOSTS_PER_WIDTH / 2 * width * boundaries
    exchange = 0 if p == 1 else 2 * (boundaries * alpha + 24 * ghosts / beta)
    reductions = 0 if p == 1 else 2 * math.ceil(math.log2(p)) * alpha * (1 + 2 / CHECK_INTERVAL)
    return compute + exchange + reductions


def efficiency(n, p, thickness, network, t_c):
    _, alpha, beta = network
    t1 = sweep_time(n, 1, thickness, alpha, beta, t_c)
    return t1 / (p * sweep_time(n, p, thickness, alpha, beta, t_c))


def step_efficiency(n, p, thickness, network, t_c):
    if p == 1:
        return 1.0
    f = WHOLE_FRACTION
    return 1 / ((1 - f) / efficiency(n, p, thickness, network, t_c) + f * p)


def main():
    t_c = T_CONTACT[64_000]
    print("Check against two ranks here (the established code's sample, 46 grains thick, tiled):")
    for n, measured in MEASURED_T2.items():
        model = sweep_time(n, 2, 46, HERE[1], HERE[2], T_CONTACT[n])
        print(f"  {n} grains: model {1e3 * model:.3f} ms per sweep, measured {1e3 * measured:.3f} ms")
    print()
    print("Efficiency E(P) of a sweep, layers 46 grains thick (the paper's), bands at least two grains:")
    ranks = [2, 4, 8, 16, 23, 32, 64, 128, 256, 1024]
    print("| grains | network | " + " | ".join(f"P = {p}" for p in ranks) + " |")
    print("|---|---|" + "---|" * len(ranks))
    for n in (16_000, 64_000, 1_000_000):
        for network in NETWORKS:
            cells = [f"{efficiency(n, p, 46, network, t_c):.2f}" if p <= 46 // 2 else "bands < 2 grains" for p in ranks]
            print(f"| {n} | {network[0]} | " + " | ".join(cells) + " |")
    print()
    print("Efficiency of a step, the same layers (the part done whole on every rank: f = "
          f"{WHOLE_FRACTION:.4f} of the one-core step):")
    print("| grains | network | " + " | ".join(f"P = {p}" for p in ranks if p <= 23) + " |")
    print("|---|---|" + "---|" * len([p for p in ranks if p <= 23]))
    for n in (64_000, 1_000_000):
        for network in NETWORKS[1:]:
            cells = [f"{step_efficiency(n, p, 46, network, t_c):.2f}" for p in ranks if p <= 23]
            print(f"| {n} | {network[0]} | " + " | ".join(cells) + " |")
    print()
    print("Grains per rank for a sweep's E = 0.8, layers 46 grains thick:")
    for p in (2, 8, 23):
        for network in NETWORKS:
            n = 46 * 2 * p  # one grain of width per band
            while efficiency(n, p, 46, network, t_c) < 0.8 and n < 1e9:
                n = int(n * 1.05) + 1
            limit = efficiency(1e12, p, 46, network, t_c)
            print(f"  P = {p}, {network[0]}: " + (f"{n / p:.0f} grains per rank" if limit >= 0.8 else
                                                  f"never (E tends to {limit:.2f}: the ghosts grow with the width as the work does)"))


if __name__ == "__main__":
    main()
