"""`forrest-biped`: Zhu, Thomas — Mechanical Design of a Biped Robot FORREST and an Extended Capture-Point-Based
Walking Pattern Generator (Robotics 2023, 12, 82).

The importable API (SI units, conf/system/forrest-biped.yaml):

    mechanisms.knee_curves / ankle_curves      the drives of Secs. 3-4 (eqs. 1-17, Figs. 8, 10-12)
    generator.pattern(walk, kind, ω, dt)        the extended and the traditional CP generator (eqs. 43-48, Sec. 5)
    model.build(system, plant=...)              FORREST from Table 4 as MJCF (simulated robot / controller's model)
    controller.WalkingController                Sec. 6: CP control, Cartesian PD, wrench QP, inverse dynamics
    walking.walk(biped, control, pattern, system)   the walk in MuJoCo (0.1 ms physics, 1 ms controller)
    lipm.simulate(pattern, k, polygons, dt)     the LIP point mass under the same CP control (the simplified check)
"""

from __future__ import annotations

from pipeline.core.experiment import NON_NEGATIVE, POSITIVE, Budget, Length, OneOf, Range, Rule, Text


def __getattr__(name: str):
    # MuJoCo, DAQP and the run files are imported only when an experiment runs
    if name == "EXPERIMENTS":
        from pipeline.papers.forrest_biped import experiments

        return {"mechanisms": experiments.mechanism_curves, "pattern-generator": experiments.pattern_generator,
                "walking": experiments.walking_runs, "robustness": experiments.walking_runs}
    raise AttributeError(name)


_M, _W, _C = "system.model.", "system.walk.", "system.controller."
LIMITS = {
    "system.gravity": Range(ge=1, le=30), "system.table1.segments": Text(), "system.table4.T": Text(),
    "system.table4.mass": NON_NEGATIVE, "system.table4.inertia": NON_NEGATIVE,
    "system.table4.com": Range(ge=-1, le=1), "system.table4.link": Range(ge=1, le=18),
    "system.table4.parent": Range(ge=0, le=17),
    _M + "translations_in": OneOf(("world",)), _M + "inertia_about": OneOf(("com", "origin")),
    _M + "link16_inertia": OneOf(("mirror", "printed")),
    "system.plant.mass_scale": Range(ge=0.5, le=2), "system.plant.inertia_about": OneOf(("com", "origin")),
    _M + "foot_length": Range(ge=0.05, le=0.5), _M + "foot_width": Range(ge=0.03, le=0.3),
    _M + "sole_depth": Range(ge=0.02, le=0.3), _M + "ankle_x": Range(ge=-0.1, le=0.1),
    _M + "corner_radius": Range(gt=0, le=0.02), _M + "friction": Range(gt=0, le=3),
    _M + "contact_solref": Range(gt=0, le=1), _M + "physics_dt": Range(ge=1e-5, le=1e-3),
    _M + "torque_limit": POSITIVE, _M + "speed_limit_rpm": POSITIVE,
    _W + "step_length": Range(ge=0.01, le=0.5), _W + "step_time": Range(ge=0.5, le=5), _W + "steps": Range(ge=0, le=10),
    _W + "foot_spacing": Range(ge=0.1, le=0.5), _W + "z_init": Range(ge=0.5, le=0.77),
    _W + "z_c": Range(ge=0.5, le=0.77),
    _W + "T1": Range(gt=0, le=0.2), _W + "T3": Range(gt=0, le=0.2),      # so that T1 + T3 < step_time
    _W + "swing_height": Range(ge=0, le=0.2), _W + "duration": Range(gt=0, le=20),
    _W + "eq48": OneOf(("corrected", "printed")),
    _C + "dt": Range(ge=1e-4, le=0.01), _C + "cp_gain": Range(ge=0, le=100),
    _C + "feedforward_com": OneOf(("desired", "measured")),
    _C + "stance_foot": OneOf(("hold", "zero")), _C + "kp_com": Range(gt=0, le=1e4),
    _C + "kp_base": Range(gt=0, le=1e4), _C + "kp_foot": Range(gt=0, le=1e5), _C + "gain_scale": Range(gt=0, le=20),
    _C + "min_normal_force": Range(ge=0, le=300), _C + "weights": POSITIVE, _C + "regularization": Range(gt=0, le=1),
    _C + "polygon_margin": Range(ge=0, le=0.05), _C + "fall_height": Range(gt=0, le=0.77),
    _C + "fall_tilt": Range(gt=0, le=1.5708),
    **{f"system.knee.{k}": POSITIVE for k in ("pitch", "spring", "spring_max_force", "upper_body_mass",
                                              "motor_torque", "motor_speed")},
    **{f"system.ankle.{k}": POSITIVE for k in ("rod", "calf", "spring", "spring_max_force", "slider_force",
                                               "slider_speed")},
    "scenario.knee_range": Range(ge=0, le=2.6), "scenario.knee_samples": Range(ge=3, le=100_000),
    "scenario.ankle_q11": Range(ge=-0.8, le=0.8), "scenario.ankle_q12": Range(ge=-0.6, le=0.6),
    "scenario.ankle_samples": Range(ge=3, le=400), "scenario.dt": Range(ge=1e-4, le=0.05),
    "scenario.generators": (Length(1, 2), OneOf(("extended", "traditional"))),
    "scenario.lipm_zmp_lags": (Length(0, 4), Range(ge=0, le=0.5)),
    "scenario.stance_foot_also": (Length(0, 2), OneOf(("hold", "zero"))),
    "scenario.window": Range(ge=0, le=20), "scenario.tf_rate_hz": Range(gt=0, le=1000),
}
RULES = (
    Rule((_W + "T1", _W + "T3", _W + "step_time"), lambda t1, t3, step: t1 + t3 < step,
         "system.walk.T1 + T3 = {0:g} + {1:g} s must leave time for the swing in a step of {2:g} s"),
    Rule((_M + "physics_dt", _C + "dt"), lambda physics, control: physics <= control,
         "system.model.physics_dt={0:g} s must not exceed the controller cycle system.controller.dt={1:g} s"),
    Rule(("scenario.window", _W + "duration"), lambda w, duration: 0 <= w[0] < w[1] <= duration,
         "scenario.window={0} must be an interval inside the walk's 0-{1:g} s"),
)


def _walk_steps(c) -> float:
    """Physics steps of the MuJoCo walks: each generator, again under each extra stance-foot setting."""
    walks = len(c.scenario.generators) * (1 + len(c.scenario.get("stance_foot_also", [])))
    return walks * c.system.walk.duration / c.system.model.physics_dt


BUDGETS = {
    "mechanisms": Budget("drive evaluations", lambda c: c.scenario.knee_samples + c.scenario.ankle_samples ** 2,
                         1e6, "fewer scenario.knee_samples or scenario.ankle_samples"),
    "pattern-generator": Budget("reference samples", lambda c: (len(c.scenario.generators) + 1)
                                * c.system.walk.duration / c.scenario.dt, 1e7, "a longer scenario.dt"),
    "walking": Budget("physics steps", _walk_steps, 5e6, "a shorter system.walk.duration or fewer generators"),
    "robustness": Budget("physics steps", _walk_steps, 5e6, "a shorter system.walk.duration or fewer generators"),
}
