"""A* on a graph with the paper's cost/heuristic pairs (Secs. 3.3, 4.2), and the same A* on the plain C-grid.

One compiled A* (`astar.py`: a binary heap of (f, vertex) on arrays, lazy deletion, re-opening of closed vertices
when a cheaper path is found, as Boost's astar_search that graph-tool wraps) serves the KG and the C-space grid alike:
both are CSR successor lists with per-edge costs and a per-vertex heuristic, so the comparison differs only in the
graph.

Metrics (the printed formulas of (11)/(12); (a), (b) are not printed: Euclidean norms):
    cspace          c = ‖C.q − C'.q‖,                 h = ‖q_goal − C.q‖, the goal vertex by Sec. 4.2.2
    tspace          c = ‖C.pos − C'.pos‖,             h = ‖P_w,g − C.pos‖
    manipulability  c = ‖ΔC.pos‖² (μ_max − μ(C'.q)),  h = ‖P_w,g − C.pos‖² (μ_max − μ(C.q))   eqs. (11), (12)
    manipulability-admissible   c = ‖ΔC.pos‖ (μ_max − μ(C'.q)),  h = max(0, ‖P_w,g − C.pos‖ − diag) · min(μ_max − μ)
The last is ours: a lower bound of the remaining cost, so A* with it returns the cheapest path.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy import sparse

from pipeline.papers.kinematic_graph.graph import voxel_box, voxel_index, voxel_keys

METRICS = ("cspace", "tspace", "manipulability", "manipulability-admissible")


# metric codes of the compiled heuristic
_CODES = {metric: k for k, metric in enumerate(METRICS)}


def heuristic_values(space, metric: str, query, q_goal: np.ndarray) -> np.ndarray:
    """The heuristic of `metric` at every vertex (what A* evaluates vertex by vertex), e.g. for Fig. 3."""
    from pipeline.papers.kinematic_graph.astar import heuristic

    goal = np.asarray(query.goal, dtype=float)
    diagonal = space.t_res * np.sqrt(space.pos.shape[1])
    return np.array([heuristic(_CODES[metric], v, space.q, space.pos, space.weight, np.asarray(q_goal, dtype=float),
                               goal, diagonal, space.w_min) for v in range(space.size)])


@dataclass
class Space:
    """What the search needs of a graph (KG or C-grid): successors and the vertex attributes, with the
    look-ups a query needs (nearest C.q, vertices of a voxel) built once."""

    successors: sparse.csr_matrix      # symmetric, sorted indices
    q: np.ndarray                      # (V, n) rad
    pos: np.ndarray                    # (V, dims) m
    voxel: np.ndarray                  # (V, dims) integer voxel coordinates
    mu: np.ndarray                     # (V,) manipulability μ(q)
    mu_max: float
    t_res: float

    def __post_init__(self) -> None:
        self.pos = np.ascontiguousarray(self.pos)
        self.weight = np.clip(self.mu_max - self.mu, 0.0, None)   # round-off must not make a cost negative
        self.w_min = float(self.weight.min()) if self.size else 0.0
        from scipy.spatial import cKDTree

        self._tree = cKDTree(self.q)
        self._box = voxel_box(self.voxel)
        keys = voxel_keys(self.voxel, self._box)
        self._order = np.argsort(keys, kind="stable")
        self._sorted_keys = keys[self._order]

    @property
    def size(self) -> int:
        return len(self.q)

    @classmethod
    def of(cls, graph, mu_max: float) -> Space:
        from pipeline.papers.kinematic_graph.graph import adjacency

        return cls(adjacency(graph.size, graph.edges), graph.q, graph.pos, graph.voxel, graph.manipulability(),
                   float(mu_max), graph.t_res)

    def edge_costs(self, metric: str) -> np.ndarray:
        """Cost of each CSR entry u -> v (the successor v is C')."""
        s = self.successors
        u = np.repeat(np.arange(self.size), np.diff(s.indptr))
        v = s.indices
        if metric == "cspace":
            return np.linalg.norm(self.q[v] - self.q[u], axis=1)
        step = np.linalg.norm(self.pos[v] - self.pos[u], axis=1)
        if metric == "tspace":
            return step
        if metric == "manipulability":
            return step ** 2 * self.weight[v]              # eq. (11)
        if metric == "manipulability-admissible":
            return step * self.weight[v]
        raise ValueError(f"unknown metric {metric!r}: one of {METRICS}")

    def start_vertex(self, q_start: np.ndarray, blocked: np.ndarray) -> int:
        """Eq. (13), with the Euclidean norm: the free vertex whose C.q is closest to q_i."""
        k = min(self.size, 32)
        _, near = self._tree.query(q_start, k=k)
        free = near[~blocked[near]]
        if len(free):
            return int(free[0])
        d = np.linalg.norm(self.q - q_start, axis=1)
        d[blocked] = np.inf
        return int(np.argmin(d))

    def goal_vertices(self, goal: np.ndarray, blocked: np.ndarray) -> np.ndarray:
        """Eq. (14): the free vertices of the voxel that holds P_w,g (its centroid within T_res/2, ∞-norm)."""
        key = voxel_keys(voxel_index(np.asarray(goal, dtype=float)[None], self.t_res), self._box)[0]
        if key < 0:
            return np.empty(0, dtype=np.int64)
        lo, hi = np.searchsorted(self._sorted_keys, key, side="left"), np.searchsorted(self._sorted_keys, key, "right")
        found = self._order[lo:hi]
        return found[~blocked[found]]


@dataclass
class Query:
    """One planning problem: the start configuration q_i and the goal position P_w,g."""

    q_start: np.ndarray
    goal: np.ndarray


@dataclass
class Plan:
    metric: str
    found: bool
    path: np.ndarray         # vertex ids, start to goal (empty if not found)
    cost: float              # in the metric's own cost
    expanded: int            # distinct vertices expanded
    met: int                 # distinct vertices queued (expanded + open)
    expansions: int
    seconds: float           # wall time of start/goal selection and A*
    reason: str = ""
    h_start: float = float("nan")   # the heuristic at the start vertex
    expanded_mask: np.ndarray | None = None
    met_mask: np.ndarray | None = None

    def explored_pct(self, size: int) -> float:
        return 100.0 * self.expanded / size


class Planner:
    """A* on one space for every metric; edge costs are computed once per metric. A search that expands
    more than `limit_factor` × |V| times (re-openings included) is stopped and reported as failed."""

    def __init__(self, space: Space, limit_factor: float = 10.0):
        self.space = space
        self.limit = int(limit_factor * space.size)
        self._costs: dict[str, np.ndarray] = {}

    def costs(self, metric: str) -> np.ndarray:
        if metric not in self._costs:
            self._costs[metric] = self.space.edge_costs(metric)
        return self._costs[metric]

    def plan(self, metric: str, query: Query, blocked: np.ndarray, keep_masks: bool = False,
             dijkstra: bool = False) -> Plan:
        """Plan from q_i to the voxel of P_w,g avoiding the `blocked` (colliding) vertices. `keep_masks` keeps the
        expanded and queued vertices on the plan (the colours of Fig. 5); `dijkstra` drops the heuristic (h = 0),
        which gives the cheapest path of the metric's costs."""
        from pipeline.papers.kinematic_graph.astar import astar, heuristic

        space, costs = self.space, self.costs(metric)
        start_time = time.perf_counter()
        start = space.start_vertex(query.q_start, blocked)
        goals = space.goal_vertices(query.goal, blocked)
        if len(goals) == 0:
            return Plan(metric, False, np.empty(0, np.int64), np.nan, 0, 0, 0, time.perf_counter() - start_time,
                        "no free vertex in the goal voxel")
        q_goal = space.q[start]
        if metric == "cspace":   # Sec. 4.2.2: the goal vertex nearest in C to q_i
            goals = goals[[np.argmin(np.linalg.norm(space.q[goals] - query.q_start, axis=1))]]
            q_goal = space.q[goals[0]]
        goal_mask = np.zeros(space.size, dtype=np.bool_)
        goal_mask[goals] = True
        diagonal = space.t_res * np.sqrt(space.pos.shape[1])
        s = space.successors
        reached, g, parent, expanded, met, expansions = astar(
            s.indptr, s.indices, costs, blocked, goal_mask, start, self.limit, -1 if dijkstra else _CODES[metric],
            space.q, space.pos,
            space.weight, q_goal, np.asarray(query.goal, dtype=float), diagonal, space.w_min)
        seconds = time.perf_counter() - start_time
        reason = {-1: "goal not connected to the start", -2: f"more than {self.limit} expansions"}.get(reached, "")
        plan = Plan(metric, reached >= 0, np.empty(0, np.int64), np.nan, np.count_nonzero(expanded),
                    np.count_nonzero(met), expansions, seconds, reason)
        plan.h_start = heuristic(_CODES[metric], start, space.q, space.pos, space.weight, q_goal,
                                 np.asarray(query.goal, dtype=float), diagonal, space.w_min)
        if keep_masks:
            plan.expanded_mask, plan.met_mask = expanded, met
        if reached >= 0:
            path = [reached]
            while path[-1] != start:
                path.append(int(parent[path[-1]]))
            plan.path, plan.cost = np.array(path[::-1]), float(g[reached])
        return plan


class TaskSpacePlanner:
    """Planning with T-space information only (what Sec. 3.4 says cannot give a feasible motion): A* over the
    occupied voxels of the KG (Moore neighbours, the `tspace` metric), avoiding the voxels an obstacle touches
    (the point P_w with the tip's radius), then the P_w path turned into joints by numerical IK, waypoint by
    waypoint from q_i (the usual pairing of a T-space planner with IK or a kinematic control loop, Sec. 1.1).
    A voxel's waypoint is the mean P_w of its nodes (a centroid near the workspace boundary can be unreachable)."""

    def __init__(self, graph, limit_factor: float = 10.0):
        from pipeline.papers.kinematic_graph.graph import moore_offsets

        self.arm, self.t_res = graph.arm, graph.t_res
        box = voxel_box(graph.voxel)
        keys = voxel_keys(graph.voxel, box)
        _, first, which = np.unique(keys, return_index=True, return_inverse=True)
        voxel = graph.voxel[first]
        weights = np.bincount(which, weights=graph.members)
        mean_pos = np.stack([np.bincount(which, weights=graph.members * graph.pos[:, k]) / weights
                             for k in range(graph.pos.shape[1])], axis=1)
        order_keys = voxel_keys(voxel, box)
        edges = []
        for d in moore_offsets(voxel.shape[1]):
            neighbour = voxel_keys(voxel + d, box)
            at = np.searchsorted(order_keys, neighbour).clip(max=len(order_keys) - 1)
            hit = (neighbour >= 0) & (order_keys[at] == neighbour)
            edges.append(np.stack([np.flatnonzero(hit), at[hit]], axis=1))
        from pipeline.papers.kinematic_graph.graph import adjacency

        self.space = Space(adjacency(len(voxel), np.concatenate(edges)), mean_pos, mean_pos, voxel,
                           np.zeros(len(voxel)), 0.0, graph.t_res)
        self.planner = Planner(self.space, limit_factor)

    def blocked(self, boxes, margin: float = 0.0) -> np.ndarray:
        """Voxels whose cube overlaps an obstacle grown by the link radius and `margin`."""
        dims = self.space.pos.shape[1]
        grow = self.t_res / 2 + self.arm.link_radius + margin
        centroids = self.space.voxel * self.t_res
        out = np.zeros(self.space.size, dtype=bool)
        for c, h in zip(boxes.centre, boxes.half, strict=True):
            out |= (np.abs(centroids - c[:dims]) <= h[:dims] + grow).all(axis=1)
        return out

    def plan(self, query: Query, blocked: np.ndarray) -> tuple[Plan, np.ndarray | None]:
        """(the voxel plan, its joint waypoints q_i … q_goal or None if the IK failed); `reason` says why."""
        from pipeline.papers.kinematic_graph.execution import ik_newton

        start_time = time.perf_counter()
        p_start = self.arm.position(query.q_start)
        plan = self.planner.plan("tspace", Query(p_start, query.goal), blocked)
        if not plan.found:
            plan.seconds = time.perf_counter() - start_time
            return plan, None
        targets = np.vstack([self.space.pos[plan.path[1:-1]], np.asarray(query.goal, dtype=float)[None]])
        joints = [np.asarray(query.q_start, dtype=float)]
        for k, target in enumerate(targets):
            q, ok = ik_newton(self.arm, joints[-1], target)
            if not ok:
                at_limit = np.isclose(q, self.arm.lower).any() or np.isclose(q, self.arm.upper).any()
                plan.found = False
                plan.reason = (f"IK stopped at a joint limit before waypoint {k + 1} of {len(targets)}" if at_limit
                               else f"IK did not reach waypoint {k + 1} of {len(targets)}")
                plan.seconds = time.perf_counter() - start_time
                return plan, None
            joints.append(q)
        plan.seconds = time.perf_counter() - start_time
        return plan, np.array(joints)
