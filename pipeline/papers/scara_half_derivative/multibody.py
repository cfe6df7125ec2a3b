"""The primary plant: the arm as an Exudyn multibody system with its parallelogram as a true closed chain.

The six links form an Exudyn `KinematicTree` (minimal coordinates of the open tree): link 1 (θ1), link 2
(θ2), bar 3 (θ3) and bar 4 (φ4) both on link 2, the coupler 5 on bar 3 (φ5), link 6 on the coupler (θ4).
The parallelogram is closed by an exact algebraic constraint between the distal pivot of bar 4 and the
coupler (the two in-plane translations: with every axis parallel, a full revolute joint would repeat three
equations), so φ4 = θ3 and φ5 = −θ3 are enforced by the solver (generalized-α, index 3), not assumed.
Actuator torques are the tree's joint forces, set once per control period (zero-order hold); the balancing
spring k3(θ3p − θ3) is the tree's proportional joint element on θ3; gravity acts on every link.
"""

from __future__ import annotations

import numpy as np

from pipeline.papers.scara_half_derivative.arm import Arm
from pipeline.robotics.exudyn_loop import SampledDataSolver, quiet_settings, stored_sensor

# tree coordinates: θ1, θ2, θ3, φ4 (bar 4 on link 2), φ5 (coupler on bar 3), θ4
TREE_PARENTS = [-1, 0, 1, 1, 2, 4]
ACTUATED = [0, 1, 2, 5]           # tree coordinates driven by actuators 1-4
# parallelogram velocity map: tree rates = LOOP @ θ̇
LOOP = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 0], [0, 0, -1, 0], [0, 0, 0, 1]], dtype=float)


def build(arm: Arm, q0, qd0):
    """(SystemContainer, mbs, handles) of the arm at θ0 moving with θ̇0."""
    import exudyn as exu
    from exudyn.itemInterface import (
        MarkerKinematicTreeRigid,
        NodeGenericODE2,
        ObjectJointGeneric,
        ObjectKinematicTree,
        VObjectJointGeneric,
        VObjectKinematicTree,
    )

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * 6, initialCoordinates=LOOP @ q0,
                                       initialCoordinates_t=LOOP @ qd0, numberOfODE2Coordinates=6))
    revolute_z, revolute_y = exu.JointType.RevoluteZ, exu.JointType.RevoluteY
    # joint frames at zero coordinates coincide with the link frames of arm.link_frames
    offsets = [[0, 0, arm.l1], [arm.l2, 0, 0], [0, 0, 0], [0, 0, arm.h], [arm.l3, 0, 0], [0, 0, 0]]
    spring = np.zeros(6)
    spring[2] = arm.k3
    neutral = np.zeros(6)
    neutral[2] = arm.theta3p
    tree = mbs.AddObject(ObjectKinematicTree(
        nodeNumber=node, gravity=[0.0, 0.0, -arm.gravity],
        jointTypes=[revolute_z, revolute_z, revolute_y, revolute_y, revolute_y, revolute_z],
        linkParents=TREE_PARENTS, jointTransformations=exu.Matrix3DList([np.eye(3)] * 6),
        jointOffsets=exu.Vector3DList(offsets), linkInertiasCOM=exu.Matrix3DList([np.diag(i) for i in arm.inertia]),
        linkCOMs=exu.Vector3DList(list(arm.com_offsets)),
        linkMasses=list(arm.masses), jointForceVector=[0.0] * 6,
        jointPControlVector=spring, jointPositionOffsetVector=neutral,   # eq. (10): k3(θ3p − θ3) on θ3
        visualization=VObjectKinematicTree(show=False)))
    bar4_tip = mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=tree, linkNumber=3, localPosition=[arm.l3, 0, 0]))
    coupler_pivot = mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=tree, linkNumber=4,
                                                           localPosition=[0, 0, arm.h]))
    closure = mbs.AddObject(ObjectJointGeneric(markerNumbers=[bar4_tip, coupler_pivot],
                                               constrainedAxes=[1, 0, 1, 0, 0, 0],   # bar 4's x and z
                                               visualization=VObjectJointGeneric(show=False)))
    # the links' centres of mass, read only by `energy` (markers that no connector uses cost the solver nothing)
    coms = [mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=tree, linkNumber=i, localPosition=c))
            for i, c in enumerate(arm.com_offsets)]
    mbs.Assemble()
    return sc, mbs, {"node": node, "tree": tree, "closure": closure, "markers": (bar4_tip, coupler_pivot),
                     "coms": coms}


class ExudynPlant:
    """The closed-chain arm behind the plant interface (`state`, `advance`, `fine`)."""

    def __init__(self, arm: Arm, q0, qd0, period: float, step: float, spectral_radius: float,
                 newton_tolerance: float):
        import exudyn as exu
        from exudyn.itemInterface import SensorNode

        self._exu = exu
        self.arm = arm
        self.sc, self.mbs, self.items = build(arm, np.asarray(q0, float), np.asarray(qd0, float))
        node = self.items["node"]
        self._sensors = [self.mbs.AddSensor(SensorNode(nodeNumber=node, outputVariableType=kind, storeInternal=True,
                                                       writeToFile=False))
                         for kind in (exu.OutputVariableType.Coordinates, exu.OutputVariableType.Coordinates_t)]
        self.mbs.Assemble()
        self.settings = quiet_settings(step, step, spectral_radius, newton_tolerance)
        self.solver = SampledDataSolver(self.mbs, self.settings, period, step)
        self._force = np.zeros(6)
        self.dt = step

    def tree_state(self) -> tuple[np.ndarray, np.ndarray]:
        """The six tree coordinates and rates now."""
        data = self.mbs.systemData
        return np.asarray(data.GetODE2Coordinates()), np.asarray(data.GetODE2Coordinates_t())

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        q, qd = self.tree_state()
        return q[ACTUATED], qd[ACTUATED]

    def advance(self, tau: np.ndarray) -> None:
        self._force[ACTUATED] = tau
        self.mbs.SetObjectParameter(self.items["tree"], "jointForceVector", self._force)
        self.solver.advance()

    def fine(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(t, θ, θ̇) at every solver step so far."""
        t, q = stored_sensor(self.mbs, self._sensors[0], self.dt)
        _, qd = stored_sensor(self.mbs, self._sensors[1], self.dt)
        return t, q[:, ACTUATED], qd[:, ACTUATED]

    def loop_residual(self) -> float:
        """Distance (m) between the two points the loop-closing joint joins, now."""
        kind = self._exu.OutputVariableType
        p = [np.asarray(self.mbs.GetMarkerOutput(m, kind.Position)) for m in self.items["markers"]]
        return float(np.linalg.norm(p[0] - p[1]))

    def energy(self) -> float:
        """Kinetic + gravity + spring energy now, from Exudyn's own link kinematics (the spring's zero at
        θ3p, gravity's at z = 0)."""
        kind, out = self._exu.OutputVariableType, self.mbs.GetMarkerOutput
        total = 0.0
        for marker, m, inertia in zip(self.items["coms"], self.arm.masses, self.arm.inertia, strict=True):
            v = np.asarray(out(marker, kind.Velocity))
            w = np.asarray(out(marker, kind.AngularVelocityLocal))
            height = out(marker, kind.Position)[2]
            total += 0.5 * m * v @ v + 0.5 * w @ (np.asarray(inertia) * w) + m * self.arm.gravity * height
        theta3 = self.tree_state()[0][2]
        return total + 0.5 * self.arm.k3 * (theta3 - self.arm.theta3p) ** 2

    def finish(self) -> None:
        self.solver.finish()
