"""kinematic-graph: graph counts against closed forms and an independent Algorithm 1, the partition invariants, A*
against Dijkstra, admissibility, analytic kinematics and collisions against MuJoCo, and bad input refused."""

from __future__ import annotations

import itertools
import math
from collections import deque

import networkx as nx
import numpy as np
import pytest
import yaml
from scipy import sparse
from scipy.sparse.csgraph import connected_components, dijkstra

from pipeline.core.checks import BadInput, preflight
from pipeline.core.experiment import CONF_DIR
from pipeline.papers.kinematic_graph import execution as ex
from pipeline.papers.kinematic_graph import graph as kgraph
from pipeline.papers.kinematic_graph.arms import RegionalArm
from pipeline.papers.kinematic_graph.collision import Boxes, MujocoChecker, planar_clearance
from pipeline.papers.kinematic_graph.search import METRICS, Planner, Query, Space, TaskSpacePlanner, heuristic_values

SYSTEM = yaml.safe_load((CONF_DIR / "system" / "kinematic-graph.yaml").read_text())
SQUARE = Boxes.from_config({"names": ["square"], "centre": [[0.45, 0.45, 0.0]], "half": [[0.05, 0.05, 0.05]]})


@pytest.fixture(scope="module")
def planar() -> RegionalArm:
    return RegionalArm.from_config("planar", SYSTEM["planar"])


@pytest.fixture(scope="module")
def puma() -> RegionalArm:
    return RegionalArm.from_config("puma", SYSTEM["puma"])


@pytest.fixture(scope="module")
def small_kg(planar):
    return kgraph.build(planar, math.radians(10), 0.1)


# -- counts: eqs. (5)-(7) -----------------------------------------------------------------------------------------


@pytest.mark.parametrize(("c_deg", "jv", "edges"), [(2.0, 181, 129_960), (1.0, 361, 519_120), (0.5, 721, 2_075_040)])
def test_grid_counts_closed_form(c_deg, jv, edges):
    values = kgraph.joint_values(-math.pi, math.pi, math.radians(c_deg))
    assert len(values) == jv and values[-1] == pytest.approx(math.pi)
    assert kgraph.grid_edge_count(jv) == 4 * jv ** 2 - 6 * jv + 2 == edges          # eq. (7)
    assert len(kgraph.moore_edges((jv, jv))) == edges
    assert len(kgraph.joint_values(-math.pi, math.pi, math.pi)) == 3


@pytest.mark.parametrize("shape", [(5, 7), (6, 6), (4, 3, 5), (4, 4, 4)])
def test_moore_grid_is_the_kings_graph(shape):
    """The Moore grid equals the strong product of paths (networkx), and its size the closed form."""
    king = nx.path_graph(shape[0])
    for n in shape[1:]:
        king = nx.strong_product(king, nx.path_graph(n))
    ours = {frozenset(e) for e in kgraph.moore_edges(shape).tolist()}
    index = {node: i for i, node in enumerate(np.ndindex(*shape))}
    assert ours == {frozenset((index[_flat(a)], index[_flat(b)])) for a, b in king.edges}
    if len(set(shape)) == 1:
        assert len(ours) == kgraph.grid_edge_count(shape[0], len(shape))


def _flat(node) -> tuple:
    """networkx nests the product's nodes: ((a, b), c) -> (a, b, c)."""
    return (*_flat(node[0]), node[1]) if isinstance(node[0], tuple) else tuple(node)


@pytest.mark.parametrize("dim", [1, 2, 3, 4])
def test_branching_factor(dim):
    degree = np.bincount(kgraph.moore_edges((3,) * dim).ravel()).max()
    assert degree == 3 ** dim - 1                                                    # eq. (5)


# -- Algorithm 1 ------------------------------------------------------------------------------------------------------


def _algorithm1_loops(arm: RegionalArm, c_res: float, t_res: float) -> tuple[int, int]:
    """Algorithm 1 as written (leastv order, BFS per voxel, edges by c_idx), with plain Python loops."""
    grid = kgraph.sample(arm, c_res)
    shape = grid.shape
    voxel = [tuple(v) for v in kgraph.voxel_index(grid.points[:, -1, : arm.task_dims], t_res).tolist()]
    nodes_of: dict[tuple, set[int]] = {}
    for n, v in enumerate(voxel):
        nodes_of.setdefault(v, set()).add(n)

    def neighbours(n: int):
        idx = np.unravel_index(n, shape)
        for d in np.ndindex(*(3,) * len(shape)):
            other = tuple(i + k - 1 for i, k in zip(idx, d, strict=True))
            if other != idx and all(0 <= o < s for o, s in zip(other, shape, strict=True)):
                yield int(np.ravel_multi_index(other, shape))

    c_idx = np.full(len(voxel), -1)
    clusters = 0
    for v in sorted(nodes_of, key=lambda v: np.linalg.norm(v)):
        left = set(nodes_of[v])
        while left:
            seed = left.pop()
            c_idx[seed] = clusters
            open_ = deque([seed])
            while open_:
                n = open_.popleft()
                for m in neighbours(n):
                    if m in left:
                        left.remove(m)
                        c_idx[m] = clusters
                        open_.append(m)
            clusters += 1
    edges = {frozenset((c_idx[n], c_idx[m])) for n in range(len(voxel)) for m in neighbours(n) if c_idx[n] != c_idx[m]}
    return clusters, len(edges)


def test_vectorised_graph_equals_algorithm_1_in_loops(planar, small_kg):
    assert (small_kg.size, len(small_kg.edges)) == _algorithm1_loops(planar, math.radians(10), 0.1)


def test_partition_invariants(planar, small_kg):
    kg = small_kg
    grid = kgraph.sample(planar, kg.c_res)
    cluster = kg.node_cluster
    assert kg.members.sum() == kg.grid_nodes == len(cluster)                       # every node in one cluster
    node_voxel = kgraph.voxel_index(grid.points[:, -1, :2], kg.t_res)
    assert (node_voxel == kg.voxel[cluster]).all()                                  # a cluster lies in one voxel
    a, b = grid.edges.T
    same_voxel = (node_voxel[a] == node_voxel[b]).all(axis=1)
    assert (cluster[a[same_voxel]] == cluster[b[same_voxel]]).all()                 # maximal within a voxel
    for c in range(0, kg.size, 7):                                                  # each cluster connected
        members = np.flatnonzero(cluster == c)
        inside = np.isin(a, members) & np.isin(b, members)
        sub = sparse.coo_matrix((np.ones(inside.sum()), (np.searchsorted(members, a[inside]),
                                                         np.searchsorted(members, b[inside]))),
                                shape=(len(members), len(members)))
        assert connected_components(sub, directed=False)[0] == 1
    assert kg.size <= kg.grid_nodes and len(kg.edges) <= kg.grid_edges
    assert kgraph.components(kg.size, kg.edges) == 1                                # the C-grid is connected
    expected = {frozenset((x, y)) for x, y in zip(cluster[a], cluster[b], strict=True) if x != y}
    assert expected == {frozenset(e) for e in kg.edges.tolist()}                    # eq. (4)
    np.testing.assert_allclose(kg.q[cluster[0]], grid.q[cluster == cluster[0]].mean(axis=0))     # eq. (9)


def test_table1_shape_and_voxel_counts(planar):
    kg = kgraph.build(planar, math.radians(1), 0.05)
    counts = np.bincount(kg.clusters_per_voxel())
    assert counts[2] / counts.sum() > 0.75          # two IK branches inside the annulus: mostly 2 clusters
    fine = kgraph.build(planar, math.radians(1), 0.01)
    l1, l2 = planar.dh.a
    annulus = math.pi * ((l1 + l2) ** 2 - (l1 - l2) ** 2) / 0.01 ** 2
    assert annulus < fine.occupied_voxels < 1.03 * annulus   # the area, plus the voxels cut by its boundary
    assert abs(kg.size / 2389 - 1) < 0.01 and abs(len(kg.edges) / 7134 - 1) < 0.01   # Table 1, 1°/0.05 m


# -- kinematics against MuJoCo --------------------------------------------------------------------------------------


def _mujoco(name: str, q0) -> tuple:
    import mujoco

    xml = ex.arm_xml(name, SYSTEM[name], SQUARE, np.asarray(q0), 1e-3, 5.0, 1.0)
    model = mujoco.MjModel.from_xml_string(xml)
    return mujoco, model, mujoco.MjData(model), xml


def test_planar_fk_and_manipulability_match_mujoco(planar):
    mujoco, model, data, _ = _mujoco("planar", [0.0, 0.0])
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "flange")
    jac = np.zeros((3, model.nv))
    l1, l2 = planar.dh.a
    for q in np.random.default_rng(0).uniform(-math.pi, math.pi, (20, 2)):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        assert np.abs(data.site_xpos[site][:2] - planar.position(q)).max() < 1e-12
        mujoco.mj_jacSite(model, data, jac, None, site)
        J = jac[:2]
        assert math.sqrt(np.linalg.det(J @ J.T)) == pytest.approx(l1 * l2 * abs(math.sin(q[1])), abs=1e-12)
        assert planar.manipulability(q) == pytest.approx(l1 * l2 * abs(math.sin(q[1])), abs=1e-12)


def test_spherical_wrist_centre(puma):
    """P_w of q1..q3 is the 6R's flange for any q4..q6 (a4 = a5 = d5 = d6 = 0), in MuJoCo too."""
    mujoco, model, data, _ = _mujoco("puma", [0.0, 0.0, 0.0])
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "flange")
    rng = np.random.default_rng(1)
    for _ in range(20):
        q = np.concatenate([rng.uniform(puma.lower, puma.upper), rng.uniform(-3, 3, 3)])
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        assert np.abs(data.site_xpos[site] - puma.position(q[:3])).max() < 1e-9
    q = rng.uniform(puma.lower, puma.upper)
    J = puma.jacobian(q)
    numeric = np.stack([(puma.position(q + 1e-7 * e) - puma.position(q - 1e-7 * e)) / 2e-7 for e in np.eye(3)], 1)
    assert np.abs(J - numeric).max() < 1e-6


def test_planar_collision_closed_form_matches_mujoco(planar):
    _, _, _, xml = _mujoco("planar", [0.0, 0.0])
    checker = MujocoChecker(xml, ex.checked_links(SYSTEM["planar"]))
    qs = np.random.default_rng(2).uniform(-math.pi, math.pi, (500, 2))
    ours = planar_clearance(planar.points(qs), SQUARE, planar.link_radius)[:, 0]
    theirs = checker.clearance(qs)[:, 0]
    apart = ours > 0
    assert apart.sum() > 400 and (~apart).sum() > 5
    assert np.abs(ours[apart] - theirs[apart]).max() < 1e-9
    assert ((checker.min_clearance(qs, 0.0) < 0) == ~apart).all()


def test_spatial_collision_matches_sampled_geometry(puma):
    box = Boxes.from_config({"names": ["block"], "centre": [[0.5, 0.2, 0.8]], "half": [[0.1, 0.15, 0.2]]})
    xml = ex.arm_xml("puma", SYSTEM["puma"], box, np.zeros(3), 1e-3, 5.0, 1.0)
    checker = MujocoChecker(xml, ex.checked_links(SYSTEM["puma"]))
    qs = np.random.default_rng(3).uniform(puma.lower, puma.upper, (200, 3))
    points = puma.points(qs)[:, 1:]                 # shoulder .. P_w: the moving links
    s = np.linspace(0, 1, 400)[:, None]
    dense = points[:, :-1, None] + s * (points[:, 1:, None] - points[:, :-1, None])      # (N, links, 400, 3)
    outside = np.maximum(np.abs(dense - box.centre[0]) - box.half[0], 0.0)
    sampled = np.linalg.norm(outside, axis=-1).min(axis=(1, 2)) - puma.link_radius
    clear = sampled > 0.01
    np.testing.assert_allclose(checker.min_clearance(qs[clear], 1.0), sampled[clear], atol=2e-3)
    assert (checker.min_clearance(qs[sampled < -0.01], 0.0) < 0).all()


# -- search -------------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def planner(planar, small_kg):
    mu_max = planar.dh.a[0] * planar.dh.a[1]
    return Planner(Space.of(small_kg, mu_max))


def _queries(arm: RegionalArm, count: int, seed: int) -> list[Query]:
    rng = np.random.default_rng(seed)
    return [Query(rng.uniform(arm.lower, arm.upper), arm.position(rng.uniform(arm.lower, arm.upper)))
            for _ in range(count)]


def _cost_matrix(planner: Planner, metric: str) -> sparse.csr_matrix:
    s = planner.space.successors
    # +1e-300: scipy drops explicit zeros, and a zero-cost edge (μ = μ_max) is still an edge
    return sparse.csr_matrix((planner.costs(metric) + 1e-300, s.indices, s.indptr), shape=s.shape)


@pytest.mark.parametrize("metric", ["cspace", "manipulability-admissible"])
def test_astar_with_an_admissible_heuristic_is_optimal(planar, planner, metric):
    free = np.zeros(planner.space.size, dtype=bool)
    costs = _cost_matrix(planner, metric)
    for query in _queries(planar, 15, 4):
        plan = planner.plan(metric, query, free)
        start = planner.space.start_vertex(query.q_start, free)
        goals = planner.space.goal_vertices(query.goal, free)
        if metric == "cspace":
            goals = goals[[np.argmin(np.linalg.norm(planner.space.q[goals] - query.q_start, axis=1))]]
        best = dijkstra(costs, indices=start)[goals].min()
        assert plan.found and plan.cost == pytest.approx(best, rel=1e-9, abs=1e-12)
        assert planner.plan(metric, query, free, dijkstra=True).cost == pytest.approx(best, rel=1e-9, abs=1e-12)
        informed, blind = plan.expanded, planner.plan(metric, query, free, dijkstra=True).expanded
        assert informed <= blind


def test_heuristics_admissible_or_not(planar, planner):
    """h ≤ the true cost-to-go everywhere for `cspace` and the admissible variant; eq. (12) overestimates."""
    free = np.zeros(planner.space.size, dtype=bool)
    query = _queries(planar, 1, 5)[0]
    goals = planner.space.goal_vertices(query.goal, free)
    for metric in ("cspace", "manipulability-admissible", "manipulability"):
        targets = goals
        if metric == "cspace":
            targets = goals[[np.argmin(np.linalg.norm(planner.space.q[goals] - query.q_start, axis=1))]]
        to_go = dijkstra(_cost_matrix(planner, metric).T, indices=targets, min_only=True)
        h = heuristic_values(planner.space, metric, query, planner.space.q[targets[0]])
        if metric == "manipulability":
            assert (h > to_go * 1.5).sum() > planner.space.size // 4      # the paper's "obviously admissible" fails
        else:
            assert (h <= to_go + 1e-12).all()


def test_paths_are_continuous_in_the_c_grid(planar, planner, small_kg):
    """Consecutive path vertices share an edge, i.e. hold C-grid neighbour nodes (the feasibility guarantee)."""
    grid = kgraph.sample(planar, small_kg.c_res)
    pairs = {frozenset(p) for p in small_kg.node_cluster[grid.edges].tolist()}
    free = np.zeros(planner.space.size, dtype=bool)
    for metric in METRICS:
        for query in _queries(planar, 5, 6):
            path = planner.plan(metric, query, free).path
            assert len(path) and all(frozenset(p) in pairs for p in itertools.pairwise(path))


def test_blocked_vertices_are_avoided(planar, small_kg, planner):
    from pipeline.papers.kinematic_graph.collision import PlanarChecker

    blocked = PlanarChecker(planar, SQUARE).blocked(small_kg, 0.0)
    assert 0 < blocked.sum() < small_kg.size
    for query in _queries(planar, 10, 7):
        plan = planner.plan("tspace", query, blocked)
        assert not plan.found or not blocked[plan.path].any()


def test_task_space_only_plan_reaches_the_goal_by_ik(planar, small_kg):
    tonly = TaskSpacePlanner(small_kg)
    query = Query(np.radians([-60.0, 100.0]), np.array([-0.55, 0.35]))
    plan, joints = tonly.plan(query, np.zeros(tonly.space.size, dtype=bool))
    assert plan.found and np.abs(planar.position(joints[-1]) - query.goal).max() < 1e-6
    # every waypoint (a voxel's mean P_w) reached; across the singular inner circle the joints may jump (Sec. 1.1)
    assert np.abs(planar.position(joints[1:-1]) - tonly.space.pos[plan.path[1:-1]]).max() < 1e-6


def test_timed_reference_passes_every_waypoint():
    waypoints = np.array([[0.0, 0.0], [0.5, 0.2], [0.6, -0.4], [1.0, -0.4]])
    ref = ex.timed_reference(waypoints, 1e-3, 1.0, 0.25, 0.2)
    np.testing.assert_allclose(ref.q[0], waypoints[0])
    np.testing.assert_allclose(ref.q[-1], waypoints[-1], atol=1e-12)
    for w, t in zip(waypoints, ref.arrival, strict=True):
        np.testing.assert_allclose(ref.q[min(round(t / 1e-3), len(ref.q) - 1)], w, atol=2e-3)
    away = np.abs(ref.times[:, None] - ref.arrival[None]).min(axis=1) > 3e-3   # the velocity turns at the corners
    np.testing.assert_allclose(np.gradient(ref.q, 1e-3, axis=0)[away], ref.qd[away], atol=0.01)


# -- bad input ------------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("override", ["scenario.c_res_deg=[0.01]", "scenario.t_res=[0]", "scenario.branching_dims=[9]"])
def test_bad_table1_input_is_refused(override):
    with pytest.raises(BadInput, match=override.split("=")[0].split(".")[-1]):
        preflight(["experiment=kinematic-graph/table1", override])


@pytest.mark.parametrize("override", ["search.pairs=100000", "search.metrics=[astar]", "graph.c_res_deg=0",
                                      "execute.speed=0", "system.planar.link_radius=-1", "search.limit_factor=1e9",
                                      "scenario.obstacles.half=[[0.05,-0.05,0.05]]", "scenario.scenes=[moon]"])
def test_bad_search_input_is_refused(override):
    with pytest.raises(BadInput) as err:
        preflight(["experiment=kinematic-graph/search", override])
    assert len(str(err.value)) < 300 and "\n" not in str(err.value)


@pytest.mark.parametrize(("args", "says"), [
    (["experiment=kinematic-graph/spatial", "graph.c_res_deg=1.5", "search.pairs=1", "search.baseline=[]"],
     "choose a coarser C_res"),
    (["experiment=kinematic-graph/table1", "scenario.c_res_deg=[0.25]", "system.planar.lower=[-6.28,-6.28]",
      "system.planar.upper=[6.28,6.28]"], "choose a coarser C_res"),
    (["experiment=kinematic-graph/search", "search.pairs=1000", "graph.c_res_deg=0.5"], "more than the budget"),
    (["experiment=kinematic-graph/search", "scenario.obstacles.names=[a,b]"], "2 names, 1 centres"),
    (["experiment=kinematic-graph/search", "execute.log_dt=0.0001"], "shorter than the physics step"),
])
def test_too_large_or_inconsistent_input_is_refused_in_one_line(args, says):
    with pytest.raises(BadInput) as err:
        preflight(args)
    assert says in str(err.value) and len(str(err.value)) < 300 and "\n" not in str(err.value)
