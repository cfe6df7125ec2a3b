"""Simulate stage of `dyad-triad-synthesis`: the worked example (Tables 4-5), the four-position Burmester
curves, synthetic round trips, the synthesised four-bar in Exudyn, and compute time. Every run logs what
the analysis needs to rebuild the paper's numbers; lengths in m, angles in rad."""

from __future__ import annotations

import fnmatch
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import yaml
from omegaconf import DictConfig

from pipeline.core import markers, schemas
from pipeline.core.experiment import Case
from pipeline.core.runlog import RunWriter, SimulationFailed
from pipeline.core.timing import time_interleaved
from pipeline.papers.dyad_triad_synthesis import burmester, fourbar, mujoco_model, multibody, synthetic
from pipeline.papers.dyad_triad_synthesis.compatibility import (
    BRANCHES,
    Compatibility,
    Root,
    Synthesized,
    classify,
    intersect,
    isotropic_roots,
    loop_table,
    reachable_intervals,
    synthesize,
    unique,
    wrapped,
)
from pipeline.papers.dyad_triad_synthesis.fourbar import LINKS, FourBar
from pipeline.papers.dyad_triad_synthesis.standard_form import dyad, link_vectors, loops, system_rank, triad

Vectors = schemas.define(
    "PlanarVectors", "Named planar vectors (complex numbers) in metres: x and y components.",
    name="string[]", x="double[] m", y="double[] m",
)
SynthesisRoot = schemas.define(
    "SynthesisRoot", "One real root of the compatibility equations: its rotations β (rad, positions 1..n), the "
    "closing assembly, what it is (trivial | special | degenerate | solution), the link vectors it gives (x, y "
    "in m, named W, Z for a dyad, W, V, Z for a triad), the residual of the linear solve (m) and its conditioning.",
    label="string", branch="int64 1", beta="double[] rad", name="string[]", x="double[] m", y="double[] m",
    residual="double m", conditioning="double 1",
)
DYAD_LINKS = ["W", "Z"]


# -- shared ---------------------------------------------------------------------------------------------


def table4(cfg: DictConfig) -> tuple[np.ndarray, np.ndarray]:
    """Table 4 in SI: precision points [m] and coupler rotations [rad]."""
    t = cfg.system.table4
    points = np.array([complex(x, y) for x, y in t.points]) * cfg.system.length_unit
    return points, np.radians(np.asarray(t.alpha_deg, dtype=float))


def search_settings(cfg: DictConfig) -> dict:
    s = cfg.system.search
    return {"grid": s.grid, "grid_2d": s.grid_2d, "same": s.same_root, "special_tol": s.special_tol,
            "conditioning": s.conditioning}


def dyads_of(found: list[Synthesized]) -> list[Synthesized]:
    return [f for f in found if f.label == "solution"]


def log_vectors(log: RunWriter, topic: str, t: float, named: dict[str, complex]) -> None:
    z = np.array(list(named.values()), dtype=complex)
    log.log(topic, t, Vectors, name=list(named), x=z.real.tolist(), y=z.imag.tolist())


def log_roots(log: RunWriter, topic: str, found: list[Synthesized], links: list[str]) -> None:
    for k, f in enumerate(found):   # root k at t = k s: the roots are a list, not a trajectory
        log.log(topic, float(k), SynthesisRoot, label=f.label, branch=f.branch, beta=f.beta.tolist(), name=links,
                x=f.vectors.real.tolist(), y=f.vectors.imag.tolist(), residual=f.residual,
                conditioning=f.conditioning)


def units_of(names, patterns: dict[str, str] | str = "1") -> list[str]:
    """Each name's unit: the first glob pattern it matches (`*.x` -> m), else a pure number."""
    if isinstance(patterns, str):
        return [patterns] * len(names)
    return [next((u for pattern, u in patterns.items() if fnmatch.fnmatchcase(n, pattern)), "1") for n in names]


def log_scalars(log: RunWriter, topic: str, t: float, values: dict[str, float],
                units: dict[str, str] | str = "1") -> None:
    log.log(topic, t, schemas.Scalars, units=units_of(values, units), name=list(values),
            value=[float(v) for v in values.values()])


def paper_four_bar(cfg: DictConfig) -> tuple[FourBar, list[dict[str, float]], np.ndarray, np.ndarray]:
    """The four-bar of the two dyads of Table 4 (A: the one with the shorter crank), and its five poses as
    rotations of crank, coupler and rocker."""
    points, alpha = table4(cfg)
    chain = dyad(points, alpha)
    found = dyads_of(synthesize(chain, **search_settings(cfg)))
    if len(found) != 2:
        raise SimulationFailed(f"Table 4 gives {len(found)} dyads, not 2: no four-bar to build")
    a, b = sorted(found, key=lambda f: abs(f.vectors[0]))
    fb = FourBar.from_dyads(points[0], tuple(a.vectors), tuple(b.vectors))
    poses = [{"crank_A": a.beta[j], "coupler": alpha[j], "rocker_B": b.beta[j]} for j in range(len(points))]
    return fb, poses, points, alpha


# -- table5: the worked example ---------------------------------------------------------------------------


def table5(cfg: DictConfig) -> list[Case]:
    points, alpha = table4(cfg)
    sc = cfg.scenario

    def simulate(log: RunWriter) -> None:
        chain = dyad(points, alpha)
        loop1, loop2 = loops(chain)
        log_vectors(log, "/synthesis/delta", 0.0, loop_table([loop1, loop2]))
        found = synthesize(chain, **search_settings(cfg))
        log_roots(log, "/synthesis/roots", found, DYAD_LINKS)
        # where each loop closes as β2 turns (Fig. 12): its four-bar with Δ2 as input
        ranges = {}
        loop_ranges = []
        for name, loop in (("delta", loop1), ("delta_prime", loop2)):
            p, q = abs(loop.shared[1]), abs(loop.last)
            arcs = reachable_intervals(loop.fixed, loop.shared[0], abs(p - q), p + q)
            loop_ranges.append(arcs)
            ranges |= {f"{name}.{i}.{end}": v for i, arc in enumerate(arcs) for end, v in zip(("lo", "hi"), arc,
                                                                                             strict=True)}
        ranges |= {f"both.{i}.{end}": v for i, arc in enumerate(intersect(*loop_ranges))
                   for end, v in zip(("lo", "hi"), arc, strict=True)}
        log_scalars(log, "/synthesis/beta2_range", 0.0, ranges, "rad")
        # the compatibility sweep: loop 2's closure residual [m] on both assemblies of loop 1 (Fig. 12-13)
        compat = Compatibility(chain)
        beta2 = np.linspace(-math.pi, math.pi, sc.sweep_samples)
        columns = [compat.evaluate(beta2[:, None], b) for b in BRANCHES]
        names = ["beta2", *(f"{k}.branch{b:+d}" for b in BRANCHES for k in ("residual", "beta3", "beta4"))]
        log.log_series("/synthesis/sweep", np.arange(len(beta2)) * 1e-3, schemas.Scalars,
                       units=units_of(names, {"residual.*": "m", "beta*": "rad"}), name=names,
                       value=np.column_stack([beta2, *(np.column_stack([r[:, 0], beta[:, 2], beta[:, 3]])
                                                       for beta, r in columns)]))
        # independent check: the Burmester circle-point condition by least squares (no cofactors)
        rng = np.random.default_rng(cfg.seed)
        direct = burmester.least_squares_dyads(points, alpha, sc.cross_check_starts, rng)
        log_vectors(log, "/synthesis/least_squares", 0.0,
                    {f"{k}.{name}": v for k, (w, z) in enumerate(direct) for name, v in (("W", w), ("Z", z))})
        # the complex roots ("six sets", Sec. 2.3)
        z = isotropic_roots([loop1, loop2])
        log_vectors(log, "/synthesis/isotropic_roots", 0.0,
                    {f"{k}.{name}": v for k, row in enumerate(z) for name, v in zip(("z2", "z3"), row, strict=True)})
        # Table 5's spread under the rounding of Table 4's printed digits
        r = sc.rounding
        for k in range(r.samples):
            dp = rng.uniform(-r.position, r.position, (len(points), 2)) * cfg.system.length_unit
            da = np.radians(rng.uniform(-r.alpha_deg, r.alpha_deg, len(alpha)))
            da[0] = 0.0
            perturbed = dyad(points + dp[:, 0] + 1j * dp[:, 1], alpha + da)
            log_vectors(log, "/synthesis/delta_rounding", k * 1e-3, loop_table(loops(perturbed)))

    return [Case("table4", simulate)]


# -- burmester-curves: four positions ------------------------------------------------------------------


def burmester_curves(cfg: DictConfig) -> list[Case]:
    points, alpha = table4(cfg)
    rows = [j - 1 for j in cfg.scenario.positions]   # four rows of Table 4 (LIMITS keep them in 1..5)
    points, alpha = points[rows], alpha[rows] - alpha[rows[0]]

    def simulate(log: RunWriter) -> None:
        chain = dyad(points, alpha)
        (loop,) = loops(chain)
        log_vectors(log, "/synthesis/delta", 0.0, loop_table([loop]))
        beta2 = np.linspace(-math.pi, math.pi, cfg.scenario.samples)
        compat = Compatibility(chain, {2: beta2})
        columns = []
        for branch in BRANCHES:
            beta = compat.evaluate(np.zeros((len(beta2), 0)), branch)[0]
            a = chain.matrix(np.nan_to_num(beta))
            w, z = np.einsum("mij,j->mi", np.linalg.pinv(a), chain.rhs[1:]).T
            ok = np.isfinite(beta).all(axis=1)
            s = np.linalg.svd(a, compute_uv=False)
            conditioning = np.where(ok, s[:, -1] / s[:, 0], np.nan)
            centre, circle = points[0] - z - w, points[0] - z
            columns += [np.where(ok, centre.real, np.nan), np.where(ok, centre.imag, np.nan),
                        np.where(ok, circle.real, np.nan), np.where(ok, circle.imag, np.nan), conditioning,
                        beta[:, 2], beta[:, 3]]
        names = [f"{k}.branch{b:+d}" for b in BRANCHES for k in ("center.x", "center.y", "circle.x", "circle.y",
                                                                   "conditioning", "beta3", "beta4")]
        log.log_series("/burmester/curves", np.arange(len(beta2)) * 1e-3, schemas.Scalars,
                       units=units_of(["beta2", *names], {"beta*": "rad", "center.*": "m", "circle.*": "m"}),
                       name=["beta2", *names],
                       value=np.column_stack([beta2, *columns]))
        log_vectors(log, "/burmester/poles", 0.0, burmester.poles(points, alpha))
        log_vectors(log, "/burmester/image_poles", 0.0, burmester.image_poles(points, alpha))
        log_vectors(log, "/burmester/pi_points", 0.0, burmester.pi_points(points, alpha))
        log_vectors(log, "/burmester/pi_points_printed", 0.0,
                    burmester.pi_points(points, alpha, burmester.PI_LINES_PRINTED))
        log_vectors(log, "/burmester/image_pi_points", 0.0,
                    burmester.pi_points(points, alpha, burmester.PI_IMAGE_LINES))
        log_vectors(log, "/burmester/positions", 0.0, {f"P{j + 1}": p for j, p in enumerate(points)})
        log_scalars(log, "/burmester/alpha", 0.0, {f"alpha{j + 1}": a for j, a in enumerate(alpha)}, "rad")

    return [Case("table4-" + "".join(map(str, cfg.scenario.positions)), simulate)]


# -- round-trips: synthetic ground truth --------------------------------------------------------------------


def _angle_error(a, b) -> float:
    return float(np.abs(wrapped(np.asarray(a) - np.asarray(b))).max())


def _closest(found: list[Synthesized], vectors: np.ndarray) -> tuple[float, int]:
    """Smallest max |link − true link| [m] over the solutions, and how many solutions there are."""
    sols = dyads_of(found)
    if not sols:
        return float("nan"), 0
    return min(float(np.abs(f.vectors - vectors).max()) for f in sols), len(sols)


def round_trips(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario
    settings = search_settings(cfg)

    def table1(log: RunWriter) -> None:
        """Table 1: free choices = unknowns − rank of the standard form's Jacobian at a solution of a random
        chain; Table 3: how many Δ vectors its compatibility loops have."""
        rng = np.random.default_rng(cfg.seed)
        values = {}
        for kind, sizes in (("dyad", range(2, 6)), ("triad", range(2, 8))):
            for n in sizes:
                if kind == "dyad":
                    sample = synthetic.random_four_bar(rng, n)
                    chain, vectors, beta = dyad(sample.points, sample.alpha), np.array(sample.dyads()[0]), sample.beta_a
                else:
                    t = synthetic.random_triad(rng, n, ungrounded=False)
                    chain, vectors, beta = triad(t.points, t.alpha, t.gamma, t.h), t.vectors, t.beta
                equations, unknowns, rank = system_rank(chain, vectors, beta)
                values |= {f"{kind}.{n}.equations": equations, f"{kind}.{n}.unknowns": unknowns,
                           f"{kind}.{n}.rank": rank, f"{kind}.{n}.free_choices": unknowns - rank}
                if n >= chain.links + 2:      # Table 3: the Δ vectors of its compatibility linkage
                    values[f"{kind}.{n}.deltas"] = len(loop_table(loops(chain)))
        log_scalars(log, "/table1", 0.0, values)

    def four_bars(log: RunWriter) -> None:
        rng = np.random.default_rng(cfg.seed)
        for k in range(sc.four_bars):
            s = synthetic.random_four_bar(rng)
            (wa, za), (wb, zb) = s.dyads()
            found5 = synthesize(dyad(s.points, s.alpha), **settings)
            err_a, n5 = _closest(found5, np.array([wa, za]))
            err_b, _ = _closest(found5, np.array([wb, zb]))
            # four positions: each true dyad at its own β2 (a point of the centre-point curve)
            chain4 = dyad(s.points[:4], s.alpha[:4])
            errors4 = []
            curve = []
            for beta_true, vectors in ((s.beta_a, np.array([wa, za])), (s.beta_b, np.array([wb, zb]))):
                found4 = synthesize(chain4, {2: beta_true[1]}, **settings)
                errors4.append(_closest(found4, vectors)[0])
                g = s.points[0] - vectors[1] - vectors[0]
                curve += [abs(float(burmester.center_point_condition(s.points, s.alpha, g))),
                          abs(float(burmester.circle_point_condition(s.points, s.alpha, s.points[0] - vectors[1])))]
            log_scalars(log, "/round_trip", float(k), {
                "dyad5.error_A": err_a, "dyad5.error_B": err_b, "dyad5.solutions": n5,
                "dyad4.error_A": errors4[0], "dyad4.error_B": errors4[1],
                "dyad4.center_condition_A": curve[0], "dyad4.circle_condition_A": curve[1],
                "dyad4.center_condition_B": curve[2], "dyad4.circle_condition_B": curve[3],
                "scale": max(abs(wa), abs(za), abs(wb), abs(zb))}, {"*.error_*": "m", "scale": "m"})

    def triads(log: RunWriter, n: int) -> None:
        rng = np.random.default_rng(cfg.seed + n)
        for k in range(sc.triads):
            t = synthetic.random_triad(rng, n, ungrounded=bool(k % 2))
            chain = triad(t.points, t.alpha, t.gamma, t.h)
            free = {5: {2: t.beta[1], 5: t.beta[4]}, 6: {2: t.beta[1]}, 7: {}}[n]
            compat = Compatibility(chain, free)
            found = synthesize(chain, free, **settings)
            best = min(found, key=lambda f: _angle_error(f.beta, t.beta))
            values = {"beta_error": _angle_error(best.beta, t.beta),
                      "vector_error": float(np.abs(link_vectors(chain, best.beta).vectors - t.vectors).max()),
                      "roots": len(found), "solutions": len(dyads_of(found)), "ungrounded": k % 2,
                      "compatibility_residual": max(float(np.abs(loop.residual(t.beta))) for loop in compat.loops),
                      "scale": float(np.abs(t.vectors).max())}
            if n == 7:   # the grid search against Newton from many random starts on all equations at once
                starts = np.zeros((sc.newton_starts, n))
                starts[:, 1:] = rng.uniform(-math.pi, math.pi, (sc.newton_starts, n - 1))
                beta = compat.newton(starts)
                from_newton = unique([Root(b, 0) for b in beta[compat.converged(beta)]], settings["same"])
                grid = [f.beta for f in found]
                missed = sum(all(_angle_error(r.beta, g) > 1e-6 for g in grid) for r in from_newton)
                values |= {"newton_roots": len(from_newton), "missed_by_grid": missed}
            log_scalars(log, "/round_trip", float(k), values, {"beta_error": "rad", "vector_error": "m",
                                                              "compatibility_residual": "m", "scale": "m"})

    def solution_counts(log: RunWriter) -> None:
        """Random five-position problems: real dyads (0, 2 or 4, Table 1) and complex roots (six, Sec. 2.3)."""
        rng = np.random.default_rng(cfg.seed)
        for k in range(sc.count_problems):
            pts = rng.uniform(-1, 1, 5) + 1j * rng.uniform(-1, 1, 5)
            al = np.concatenate([[0.0], np.cumsum(rng.uniform(0.05, 0.8, 4))])
            chain = dyad(pts, al)
            found = synthesize(chain, **settings)
            z = isotropic_roots(loops(chain))
            real = np.abs(np.abs(z) - 1).max(axis=1) < 1e-7
            log_scalars(log, "/solution_count", float(k), {
                "real_dyads": len(dyads_of(found)), "real_roots": len(found), "complex_roots": len(z),
                "complex_roots_real": int(real.sum())})

    return [Case("table1", table1), Case("four-bars", four_bars),
            *(Case(f"triad-{n}pp", lambda log, n=n: triads(log, n)) for n in (5, 6, 7)),
            Case("solution-counts", solution_counts)]


# -- four-bar: closed form and Exudyn ------------------------------------------------------------------------


def _defects(log: RunWriter, fb: FourBar, poses: list[dict[str, float]]) -> None:
    values = {"grashof_margin": fb.grashof_margin(), **{f"length.{k}": v for k, v in fb.lengths.items()}}
    for driver in fourbar.DRIVERS:
        link = LINKS[0] if driver == "A" else LINKS[2]
        lo, hi = fb.driver_range(driver)
        places = fourbar.circuit_order(fb, driver, poses)
        values |= {f"{driver}.range.lo": lo, f"{driver}.range.hi": hi,
                   f"{driver}.order_kept": float(fourbar.cyclic_order_kept(places))}
        for j, pose in enumerate(poses, start=1):
            values[f"{driver}.branch.{j}"] = float(fb.branch_at(driver, fourbar.on_arc(pose[link], (lo, hi)),
                                                                pose["coupler"])[0])
            values[f"{driver}.circuit_place.{j}"] = float(places[j - 1])
        for j in range(1, len(poses)):
            leg = fourbar.leg(fb, driver, poses[j - 1], poses[j])
            s = leg.samples(fb)
            mu = fb.transmission_angle(s, driver)
            values |= {f"{driver}.leg{j}{j + 1}.toggles": leg.toggles,
                       f"{driver}.leg{j}{j + 1}.path_length": float(np.abs(np.diff(s["p"])).sum()),
                       f"{driver}.leg{j}{j + 1}.transmission.min": float(mu.min()),
                       f"{driver}.leg{j}{j + 1}.transmission.max": float(mu.max()),
                       f"{driver}.leg{j}{j + 1}.coupler_monotonic": float(np.all(np.diff(s["coupler"]) > 0)
                                                                          or np.all(np.diff(s["coupler"]) < 0))}
    log_scalars(log, "/defects", 0.0, values, {"grashof_margin": "m", "length.*": "m", "*.range.*": "rad",
                                               "*.path_length": "m", "*.transmission.*": "rad"})


def _quintic(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rest-to-rest quintic on s ∈ [0, 1]: position, d/ds, d²/ds²."""
    s = np.clip(s, 0.0, 1.0)
    return s ** 3 * (10 - 15 * s + 6 * s ** 2), 30 * s ** 2 * (1 - s) ** 2, 60 * s * (1 - s) * (1 - 2 * s)


def _frames(model: multibody.ExudynFourBar, q: np.ndarray) -> np.ndarray:
    """(N, 4, 4, 4) poses of crank, coupler, rocker and tracer frames in the world: each at its link's first
    joint (a0, a1, b0; the tracer at p), turned by the link's rotation from position 1."""
    f = model.fourbar
    origins = [(0, f.a0), (1, f.a1), (2, f.b0), (1, f.p)]
    out = np.tile(np.eye(4), (len(q), len(origins), 1, 1))
    for k, (body, point) in enumerate(origins):
        z = multibody.points_of(model.bodies, q, body, point)
        phi = q[:, body, 2]
        out[:, k, 0, 0], out[:, k, 0, 1], out[:, k, 1, 0], out[:, k, 1, 1] = (np.cos(phi), -np.sin(phi),
                                                                               np.sin(phi), np.cos(phi))
        out[:, k, 0, 3], out[:, k, 1, 3] = z.real, z.imag
    return out


FRAMES = ["crank_A", "coupler", "rocker_B", "tracer"]


def _scene(path: np.ndarray, targets: np.ndarray, radius: float):
    """The pivots as spheres, the precision points and the tracer's path (the links are the model's URDF)."""
    return schemas.SceneUpdate(entities=[
        *markers.spheres(["crank_A", "rocker_B", "tracer"], [2 * radius] * 3, [(0.1, 0.1, 0.1, 1.0)] * 3),
        markers.line_strip("tracer_path", np.column_stack([path.real, path.imag, np.zeros(len(path))]),
                           thickness=radius / 2, color=(0.8, 0.1, 0.1, 1.0)),
        markers.line_strip("precision_points", np.column_stack([targets.real, targets.imag, np.zeros(len(targets))]),
                           thickness=radius / 4, color=(0.1, 0.1, 0.1, 0.6)),
    ])


def _model_yaml(model: multibody.ExudynFourBar, cfg: DictConfig) -> str:
    """The Exudyn model's parameters, attached to the run (the model is generated from them)."""
    f = model.fourbar
    pivots = {k: [float(getattr(f, k).real), float(getattr(f, k).imag)] for k in ("a0", "a1", "b0", "b1", "p")}
    return yaml.safe_dump({
        "pivots_m": pivots, "line_density_kg_per_m": float(cfg.system.linkage.line_density),
        "bodies": [{"name": b.name, "mass_kg": b.mass, "com_m": [b.com.real, b.com.imag],
                    "inertia_kg_m2": b.inertia} for b in model.bodies],
        "joints": ["revolute a0 ground-crank", "revolute a1 crank-coupler", "revolute b1 coupler-rocker",
                   "revolute b0 rocker-ground"],
        "gravity": 0.0}, sort_keys=False)


def _log_motion(log: RunWriter, cfg: DictConfig, model: multibody.ExudynFourBar, t: np.ndarray, q: np.ndarray,
                qd: np.ndarray, reference: dict[str, np.ndarray], driver_of: np.ndarray, branch_of: np.ndarray,
                targets: np.ndarray) -> None:
    """Joint state, reference, tracking errors (driver; tracer against the closed-form analysis at the
    driver's actual rotation), joint gaps, link frames and the scene, every log_dt / tf_dt."""
    ex = cfg.execute
    dt = float(np.median(np.diff(t)))
    every = slice(None, None, max(1, round(ex.log_dt / dt)))
    ts, qs, qds = t[every], q[every], qd[every]
    log.log_series("/joint_state", ts, units="rad", name=list(LINKS), position=qs[:, :, 2], velocity=qds[:, :, 2])
    names = reference["name"]
    log.log_series("/reference", ts, units="rad", name=list(names), position=reference["position"][every],
                   velocity=reference["velocity"][every], acceleration=reference["acceleration"][every])
    driven = np.where(driver_of[every] == "A", qs[:, 0, 2], qs[:, 2, 2])
    err = reference["position"][every][:, 0] - driven
    log.log_series("/tracking_error", ts, units="rad", name=["driver"], error=err[:, None], norm=np.abs(err))
    # the tracer and coupler against the closed-form analysis at the same driver rotation and branch
    tracer = multibody.points_of(model.bodies, qs, 1, model.fourbar.p)
    closed = np.empty(len(ts), dtype=complex)
    coupler = np.empty(len(ts))
    for d in fourbar.DRIVERS:
        for b in BRANCHES:
            sel = (driver_of[every] == d) & (branch_of[every] == b)
            if sel.any():
                c = model.fourbar.solve(d, driven[sel], b)
                closed[sel], coupler[sel] = c["p"], c["coupler"]
    dp = tracer - closed
    da = np.remainder(qs[:, 1, 2] - coupler + math.pi, 2 * math.pi) - math.pi
    log.log_series("/tracking_error/closed_form", ts, units=["m", "m", "rad"], field_units={"norm": "m"},
                   name=["x", "y", "coupler"],
                   error=np.column_stack([dp.real, dp.imag, da]), norm=np.abs(dp))
    gaps = multibody.joint_gaps(model, qs)
    log.log_series("/joint_gap", ts, schemas.Scalars, units="m", name=["a0", "a1", "b1", "b0"], value=gaps)
    tf = slice(None, None, max(1, round(ex.tf_dt / dt)))
    log.log_transforms(t[tf], "world", FRAMES, _frames(model, q[tf]))
    log.attach("model.xml", mujoco_model.model_xml(model.fourbar, model.bodies, cfg.system.linkage.link_radius),
               "application/xml")
    log.log_robot(t[tf], mujoco_model.qpos(q[tf, :, 2]))
    path = multibody.points_of(model.bodies, q[tf], 1, model.fourbar.p)
    log.write("/markers", 0, _scene(path, targets, cfg.system.linkage.link_radius))


def _arrivals(log: RunWriter, model: multibody.ExudynFourBar, t: np.ndarray, q: np.ndarray,
              arrivals: list[tuple[int, float, str, int]], points: np.ndarray, alpha: np.ndarray) -> None:
    """At each precision position the run stops on: the tracer and coupler against the paper's pose and
    against the closed-form analysis (the driver's rotation, same branch)."""
    for j, t_j, driver, branch in arrivals:
        k = int(np.argmin(np.abs(t - t_j)))
        qk = q[k:k + 1]
        p = multibody.points_of(model.bodies, qk, 1, model.fourbar.p)[0]
        rotation = qk[0, 0 if driver == "A" else 2, 2]
        c = model.fourbar.solve(driver, rotation, branch)
        log_scalars(log, "/precision_position", float(t[k]), {
            "position": j, "target.x": points[j - 1].real, "target.y": points[j - 1].imag,
            "target.alpha": alpha[j - 1], "sim.x": p.real, "sim.y": p.imag, "sim.alpha": qk[0, 1, 2],
            "closed_form.x": complex(c["p"]).real, "closed_form.y": complex(c["p"]).imag,
            "closed_form.alpha": float(c["coupler"]), "driver_rotation": rotation,
            "joint_gap": float(multibody.joint_gaps(model, qk).max())},
            {"*.x": "m", "*.y": "m", "*.alpha": "rad", "driver_rotation": "rad", "joint_gap": "m"})


def four_bar(cfg: DictConfig) -> list[Case]:
    sc, ex, link = cfg.scenario, cfg.execute, cfg.system.linkage

    def defects(log: RunWriter) -> None:
        fb, poses, _, _ = paper_four_bar(cfg)
        _defects(log, fb, poses)
        # the whole circuit (closed form), for the figure: driver B out on one branch and back on the other
        lo, hi = fb.driver_range("B")
        x = np.linspace(lo, hi, 721)
        rows = []
        for b in BRANCHES:
            c = fb.solve("B", x if b == 1 else x[::-1], b)
            rows.append(np.column_stack([c["p"].real, c["p"].imag, c["crank_A"], c["coupler"], c["rocker_B"]]))
        log.log_series("/circuit", np.arange(2 * len(x)) * 1e-3, schemas.Scalars, units=["m", "m", "rad", "rad", "rad"],
                       name=["tracer.x", "tracer.y", *LINKS], value=np.concatenate(rows))

    def replay(log: RunWriter) -> None:
        fb, poses, points, alpha = paper_four_bar(cfg)
        legs = [fourbar.leg(fb, "A", poses[0], poses[1])]
        legs += [fourbar.leg(fb, "B", poses[j], poses[j + 1]) for j in range(1, len(poses) - 1)]
        if any(leg.toggles for leg in legs):
            raise SimulationFailed("a replay leg needs a toggle of its driver: the drive cannot pass it")
        model = multibody.ExudynFourBar(fb, link.line_density, ex.dt, ex.dt, ex.spectral_radius, ex.newton_tolerance)
        log.attach("model.yaml", _model_yaml(model, cfg), "application/yaml")
        steps = round(sc.leg_duration / ex.dt)
        s = np.arange(1, steps + 1) / steps
        shape, rate, accel = _quintic(s)
        ref = {"name": ["driver"], "position": [np.zeros(1)], "velocity": [np.zeros(1)],
               "acceleration": [np.zeros(1)]}
        driver_of, branch_of = [legs[0].driver], [legs[0].branches[0]]
        arrivals = []
        try:
            for j, leg in enumerate(legs, start=2):
                model.drive(leg.driver)
                start = model.rotations()[0 if leg.driver == "A" else 2]
                span = leg.end - leg.start
                for x in start + span * shape:
                    model.advance(x)
                ref["position"].append(start + span * shape)
                ref["velocity"].append(span * rate / sc.leg_duration)
                ref["acceleration"].append(span * accel / sc.leg_duration ** 2)
                driver_of += [leg.driver] * steps
                branch_of += [leg.branches[0]] * steps
                arrivals.append((j, (j - 1) * sc.leg_duration, leg.driver, leg.branches[0]))
        finally:
            model.finish()
        t, q, qd = model.fine()
        reference = {k: (np.concatenate(v)[:, None] if k != "name" else v) for k, v in ref.items()}
        _log_motion(log, cfg, model, t, q, qd, reference, np.array(driver_of), np.array(branch_of), points)
        _arrivals(log, model, t, q, [(1, 0.0, "A", legs[0].branches[0]), *arrivals], points, alpha)

    def servo(log: RunWriter, controller: str) -> None:
        fb, poses, points, alpha = paper_four_bar(cfg)
        run = servo_2to5(cfg, fb, poses, controller)
        log.attach("model.yaml", _model_yaml(run.model, cfg), "application/yaml")
        log_servo(log, cfg, run, points, alpha)

    return [Case("defects", defects), Case("replay-1to5", replay),
            *(Case(f"servo-2to5-{c}", lambda log, c=c: servo(log, c)) for c in sc.controllers)]


@dataclass
class ServoRun:
    """The 2→5 servo run: the model, its fine-step samples, the reference and the torques per period."""

    model: multibody.ExudynFourBar
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    reference: dict
    torque: np.ndarray
    branch: int


def servo_2to5(cfg: DictConfig, fb: FourBar, poses: list[dict[str, float]], controller: str) -> ServoRun:
    """The rocker servoed from pose 2 to pose 5 (rest-to-rest quintic, then held): PD with gains scaled by the
    reduced inertia J, and for `computed-torque` the model's J(q_ref) q̈_ref + ½ J'(q_ref) q̇_ref² added."""
    sc, ex = cfg.scenario, cfg.execute
    legs = [fourbar.leg(fb, "B", poses[j], poses[j + 1]) for j in range(1, len(poses) - 1)]
    if any(leg.toggles for leg in legs) or len({leg.branches[0] for leg in legs}) != 1:
        raise SimulationFailed("poses 2-5 are not on one branch of the rocker drive")
    branch = legs[0].branches[0]
    start_rotation, end_rotation = legs[0].start, legs[-1].end
    model = multibody.ExudynFourBar(fb, cfg.system.linkage.line_density, ex.servo_dt, ex.control_dt,
                                    ex.spectral_radius, ex.newton_tolerance,
                                    start=fb.solve("B", start_rotation, branch))
    periods = round((sc.move_duration + sc.hold_duration) / ex.control_dt)
    t_ref = np.arange(periods + 1) * ex.control_dt
    shape, rate, accel = _quintic(t_ref / sc.move_duration)
    span = end_rotation - start_rotation
    q_ref = start_rotation + span * shape
    qd_ref, qdd_ref = span * rate / sc.move_duration, span * accel / sc.move_duration ** 2
    j_ref, dj_ref = multibody.reduced_inertia(fb, model.bodies, "B", q_ref, branch)
    omega = 2 * math.pi * ex.bandwidth_hz
    kp, kd = omega ** 2, 2 * ex.damping_ratio * omega
    torque = np.zeros(periods)
    try:
        for k in range(periods):
            q, qd = model.state()
            e, ed = q_ref[k] - q[2, 2], qd_ref[k] - qd[2, 2]
            if controller == "computed-torque":   # on the reference, from the closed-form model
                torque[k] = j_ref[k] * (qdd_ref[k] + kd * ed + kp * e) + 0.5 * dj_ref[k] * qd_ref[k] ** 2
            else:
                torque[k] = j_ref[0] * (kd * ed + kp * e)
            model.advance(torque=torque[k])
    finally:
        model.finish()
    t, q, qd = model.fine()
    k_ref = np.minimum(np.rint(t / ex.control_dt).astype(int), periods)
    reference = {"name": ["rocker_B"], "position": q_ref[k_ref][:, None], "velocity": qd_ref[k_ref][:, None],
                 "acceleration": qdd_ref[k_ref][:, None]}
    return ServoRun(model, t, q, qd, reference, torque, branch)


def log_servo(log: RunWriter, cfg: DictConfig, run: ServoRun, points: np.ndarray, alpha: np.ndarray) -> None:
    """The servo run's motion and torques, and its passage through positions 2..5 (the tracer's closest
    approach, the coupler's error there)."""
    t, q = run.t, run.q
    _log_motion(log, cfg, run.model, t, q, run.qd, run.reference, np.full(len(t), "B"), np.full(len(t), run.branch),
                points)
    log.log_series("/command", np.arange(len(run.torque)) * cfg.execute.control_dt, units="rad", kind="torque",
                   name=["rocker_B"], value=run.torque[:, None])
    tracer = multibody.points_of(run.model.bodies, q, 1, run.model.fourbar.p)
    for j in range(2, len(points) + 1):
        k = int(np.argmin(np.abs(tracer - points[j - 1])))
        log_scalars(log, "/passage", float(t[k]), {
            "position": j, "distance": abs(tracer[k] - points[j - 1]),
            "coupler_error": math.remainder(q[k, 1, 2] - alpha[j - 1], 2 * math.pi)},
            {"distance": "m", "coupler_error": "rad"})


# -- compute-time ------------------------------------------------------------------------------------------


def solvers(cfg: DictConfig) -> dict[str, Callable[[np.ndarray, np.ndarray], list[np.ndarray]]]:
    """The dyad in five positions solved three ways: (points, α) -> the finite dyads [W, Z] each finds."""
    sc = cfg.scenario
    settings = search_settings(cfg)

    def sweep(p, a):
        return [f.vectors for f in dyads_of(synthesize(dyad(p, a), **settings))]

    def least_squares(p, a):
        return [np.array(d) for d in burmester.least_squares_dyads(p, a, sc.least_squares_starts,
                                                                   np.random.default_rng(cfg.seed))]

    def newton(p, a):
        chain = dyad(p, a)
        compat = Compatibility(chain)
        starts = np.zeros((sc.newton_starts, chain.n))
        starts[:, 1:] = np.random.default_rng(cfg.seed).uniform(-math.pi, math.pi, (sc.newton_starts, chain.n - 1))
        beta = compat.newton(starts)
        roots = unique([Root(b, 0) for b in beta[compat.converged(beta)]], settings["same"])
        return [link_vectors(chain, r.beta).vectors for r in roots
                if classify(chain, r.beta, settings["special_tol"], settings["conditioning"]) == "solution"]

    return {"compatibility_sweep": sweep, "least_squares": least_squares, "random_newton": newton}


def compute_time(cfg: DictConfig) -> list[Case]:
    sc = cfg.scenario

    def simulate(log: RunWriter) -> None:
        rng = np.random.default_rng(cfg.seed)
        points, alpha = table4(cfg)
        problems = [("table4", points, alpha)]
        for k in range(sc.problems):
            s = synthetic.random_four_bar(rng)
            problems.append((f"four-bar-{k}", s.points, s.alpha))

        methods = solvers(cfg)
        t = 0.0
        for k, (name, p, a) in enumerate(problems):
            timings = time_interleaved({m: (fn, (p, a), 1) for m, fn in methods.items()}, warmup=1,
                                       repeats=sc.repeats)
            reference = methods["compatibility_sweep"](p, a)
            found = {}
            for m, fn in methods.items():
                dyads = fn(p, a)
                hits = sum(any(np.abs(d - r).max() < 1e-6 * np.abs(r).max() for d in dyads) for r in reference)
                found |= {f"{m}.dyads": len(dyads), f"{m}.found_of_reference": hits}
            log_scalars(log, "/solvers", float(k), {"problem": k, "reference_dyads": len(reference), **found})
            for m, timing in timings.items():
                times = t + np.arange(len(timing.seconds)) * 1e-3
                log.log_series("/compute_time", times, name=[f"{m}.{name}"], calls=[1],
                               seconds=timing.seconds[:, None])
                t = float(times[-1]) + 1e-3

    return [Case("dyad-5pp", simulate)]

