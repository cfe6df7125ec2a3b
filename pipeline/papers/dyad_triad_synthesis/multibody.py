"""The synthesised four-bar as an Exudyn multibody system: a true closed loop with exact constraints.

Three planar rigid bodies (crank a0→a1, the coupler triangle a1-b1-p, rocker b0→b1; uniform rods of a
given mass per length) joined by four revolute joints to each other and to the ground. Each body's node
sits at its centre of mass with zero reference rotation in position 1, so its rotation coordinate is the
link's rotation from position 1: β_A, α, β_B of the standard form. The implicit solver (generalized-α,
index-3) keeps every joint closed to Newton tolerance.

Drives, set once per control period (zero-order hold):
- `driver`: a coordinate constraint holds the crank's (A) or the rocker's (B) rotation at a prescribed
  value (kinematic replay; the constraint's offset is the reference at the end of the period);
- `torque`: a generalized force on the rocker's rotation (the servo).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.papers.dyad_triad_synthesis.fourbar import LINKS, FourBar
from pipeline.robotics.exudyn_loop import SampledDataSolver, quiet_settings, stored_sensor


@dataclass(frozen=True)
class Body:
    name: str
    points: tuple[complex, ...]    # the body's joints (and tracer) in position 1 [m]
    mass: float                    # kg
    com: complex                   # m
    inertia: float                 # kg m^2 about the centre of mass


def rod_body(name: str, points: tuple[complex, ...], line_density: float) -> Body:
    """A rigid body made of uniform rods joining consecutive points (closed, for three or more points)."""
    ends = list(zip(points, points[1:] + points[:1], strict=True)) if len(points) > 2 else [points]
    lengths = np.array([abs(b - a) for a, b in ends])
    mids = np.array([(a + b) / 2 for a, b in ends])
    masses = line_density * lengths
    com = complex((masses * mids).sum() / masses.sum())
    inertia = float((masses * lengths ** 2 / 12 + masses * np.abs(mids - com) ** 2).sum())
    return Body(name, points, float(masses.sum()), com, inertia)


def bodies(fourbar: FourBar, line_density: float) -> list[Body]:
    """Crank, coupler, rocker, in the order of LINKS."""
    f = fourbar
    return [rod_body(LINKS[0], (f.a0, f.a1), line_density), rod_body(LINKS[1], (f.a1, f.b1, f.p), line_density),
            rod_body(LINKS[2], (f.b0, f.b1), line_density)]


def _xy(z: complex) -> list[float]:
    return [z.real, z.imag, 0.0]


def displacements(fourbar: FourBar, bodies_: list[Body], config: dict[str, np.ndarray]) -> np.ndarray:
    """Node coordinates (3 bodies × [x, y, φ], displacements from position 1) of a closed-form configuration."""
    anchors = [(fourbar.a0, fourbar.a0), (fourbar.a1, complex(config["a1"])), (fourbar.b0, fourbar.b0)]
    out = np.zeros((3, 3))
    for k, (b, (old, new)) in enumerate(zip(bodies_, anchors, strict=True)):
        phi = float(config[LINKS[k]])
        com = new + (b.com - old) * np.exp(1j * phi)
        out[k] = [(com - b.com).real, (com - b.com).imag, phi]
    return out


class ExudynFourBar:
    """The four-bar in Exudyn, at rest in position 1 or in a given closed-form configuration."""

    def __init__(self, fourbar: FourBar, line_density: float, step: float, period: float, spectral_radius: float,
                 newton_tolerance: float, start: dict[str, np.ndarray] | None = None):
        import exudyn as exu
        from exudyn.itemInterface import (
            LoadCoordinate,
            MarkerBodyPosition,
            MarkerNodeCoordinate,
            NodePointGround,
            NodeRigidBody2D,
            ObjectConnectorCoordinate,
            ObjectGround,
            ObjectJointRevolute2D,
            ObjectRigidBody2D,
            SensorNode,
        )

        self.fourbar, self.bodies, self.dt = fourbar, bodies(fourbar, line_density), step
        self.sc = exu.SystemContainer()
        mbs = self.mbs = self.sc.AddSystem()
        ground = mbs.AddObject(ObjectGround())
        initial = np.zeros((3, 3)) if start is None else displacements(fourbar, self.bodies, start)
        nodes, objects = [], []
        for b, q0 in zip(self.bodies, initial, strict=True):
            nodes.append(mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[b.com.real, b.com.imag, 0.0],
                                                     initialCoordinates=q0.tolist())))
            objects.append(mbs.AddObject(ObjectRigidBody2D(nodeNumber=nodes[-1], mass=b.mass, inertia=b.inertia)))

        def marker(body: int | None, point: complex) -> int:
            if body is None:
                return mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=_xy(point)))
            return mbs.AddMarker(MarkerBodyPosition(bodyNumber=objects[body],
                                                    localPosition=_xy(point - self.bodies[body].com)))

        f = fourbar
        self.joints = [(None, 0, f.a0), (0, 1, f.a1), (1, 2, f.b1), (2, None, f.b0)]
        for i, j, point in self.joints:
            mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[marker(i, point), marker(j, point)]))
        fixed = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
        rotation = [mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=n, coordinate=2)) for n in nodes]
        # coordinate drives of the crank (A) and the rocker (B), off until `drive` picks one
        self.drives = {"A": mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[fixed, rotation[0]],
                                                                    activeConnector=False)),
                       "B": mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[fixed, rotation[2]],
                                                                    activeConnector=False))}
        self.torque = mbs.AddLoad(LoadCoordinate(markerNumber=rotation[2], load=0.0))
        kinds = (exu.OutputVariableType.Coordinates, exu.OutputVariableType.Coordinates_t)
        self.sensors = [[mbs.AddSensor(SensorNode(nodeNumber=n, outputVariableType=k, storeInternal=True,
                                                  writeToFile=False)) for n in nodes] for k in kinds]
        mbs.Assemble()
        self.settings = quiet_settings(step, step, spectral_radius, newton_tolerance)
        self.period = period
        self.solver: SampledDataSolver | None = None
        self.active: str | None = None

    def drive(self, driver: str | None) -> None:
        """Hold the crank (A) or the rocker (B) by its coordinate constraint from now on (None: free); the
        constraint starts at the link's present rotation."""
        for name, item in self.drives.items():
            on = name == driver
            if on:
                self.mbs.SetObjectParameter(item, "offset", float(self.rotations()[0 if name == "A" else 2]))
            self.mbs.SetObjectParameter(item, "activeConnector", on)
        self.active = driver

    def advance(self, reference: float | None = None, torque: float = 0.0) -> None:
        """One control period with the active drive held at `reference` [rad] at its end and `torque` [N m] on
        the rocker."""
        if self.solver is None:
            self.solver = SampledDataSolver(self.mbs, self.settings, self.period, self.dt)
        if self.active is not None and reference is not None:
            self.mbs.SetObjectParameter(self.drives[self.active], "offset", float(reference))
        self.mbs.SetLoadParameter(self.torque, "load", float(torque))
        self.solver.advance()

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        """Node coordinates (3 bodies × [x, y, φ] displacements) and their rates now."""
        data = self.mbs.systemData
        return (np.asarray(data.GetODE2Coordinates()).reshape(3, 3),
                np.asarray(data.GetODE2Coordinates_t()).reshape(3, 3))

    def rotations(self) -> np.ndarray:
        return self.state()[0][:, 2]

    def fine(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(t, q, q̇) at every solver step so far: q, q̇ of shape (N, 3 bodies, 3) [m, m, rad]."""
        t = None
        out = []
        for group in self.sensors:
            cols = []
            for s in group:
                t, v = stored_sensor(self.mbs, s, self.dt)
                cols.append(v)
            out.append(np.stack(cols, axis=1))
        return t, out[0], out[1]

    def finish(self) -> None:
        if self.solver is not None:
            self.solver.finish()


def points_of(bodies_: list[Body], q: np.ndarray, body: int, point: complex) -> np.ndarray:
    """World position [m] of a body point (given in position 1) for node coordinates q (N, 3, 3)."""
    b = bodies_[body]
    centre = b.com + q[:, body, 0] + 1j * q[:, body, 1]
    return centre + (point - b.com) * np.exp(1j * q[:, body, 2])


def joint_gaps(model: ExudynFourBar, q: np.ndarray) -> np.ndarray:
    """Distance [m] between the two bodies' points of each revolute joint, (N, 4)."""
    gaps = []
    for i, j, point in model.joints:
        pi = np.full(len(q), point) if i is None else points_of(model.bodies, q, i, point)
        pj = np.full(len(q), point) if j is None else points_of(model.bodies, q, j, point)
        gaps.append(np.abs(pi - pj))
    return np.stack(gaps, axis=1)


def reduced_inertia(fourbar: FourBar, bodies_: list[Body], driver: str, rotation: np.ndarray, branch: int,
                    h: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """J(θ) [kg m²] and dJ/dθ of the loop seen from the driver's rotation θ, from the closed-form position
    analysis: the kinetic energy is ½ J(θ) θ̇², so the motion obeys J θ̈ + ½ J' θ̇² = τ (no gravity)."""
    def inertia(x: np.ndarray) -> np.ndarray:
        configs = [fourbar.solve(driver, x + s, branch) for s in (-h, h)]
        total = np.zeros(len(x))
        for k, b in enumerate(bodies_):
            rot = [c[LINKS[k]] for c in configs]
            anchor = [fourbar.a0 if k == 0 else (c["a1"] if k == 1 else fourbar.b0) for c in configs]
            lever = {0: fourbar.a0, 1: fourbar.a1, 2: fourbar.b0}[k]
            com = [a + (b.com - lever) * np.exp(1j * r) for a, r in zip(anchor, rot, strict=True)]
            v = (com[1] - com[0]) / (2 * h)
            w = (rot[1] - rot[0]) / (2 * h)
            total += b.mass * np.abs(v) ** 2 + b.inertia * w ** 2
        return total

    rotation = np.asarray(rotation, dtype=float)
    j = inertia(rotation)
    dj = (inertia(rotation + 1e3 * h) - inertia(rotation - 1e3 * h)) / (2e3 * h)
    return j, dj
