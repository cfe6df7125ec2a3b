"""Algorithm 1: the kinematic graph 𝔊_k(𝔙_k, 𝔈_k), built with whole-array operations.

1. SampleConfigSpace: a regular joint grid at C_res (List 2), Moore neighbourhood (b = 3^dim − 1, eq. 5).
2. FK of every node (line 2), ApproximateTaskSpace: each node in one voxel of edge T_res, centroids at integer
   multiples of T_res, ties to the voxel with the smaller centroid norm (the text's rule; lines 7-14).
3. ConstructVertices: the clusters of a voxel are the connected components of the C-grid restricted to its
   nodes (the BFS of lines 15-37), found at once for all voxels by one connected-components pass over the
   grid edges whose two nodes share a voxel.
4. ConstructKinematicGraph: two clusters are joined when any of their nodes are C-grid neighbours (eq. 4).

Vertex attributes: C.q (eq. 9), C.pos (eq. 8), the mean critical points (elbow, …) for collision checks
(Sec. 3.3), μ(C.q) (eq. 10), the voxel centroid.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse
from scipy.sparse.csgraph import connected_components

from pipeline.papers.kinematic_graph.arms import RegionalArm


def joint_values(lower: float, upper: float, resolution: float) -> np.ndarray:
    """`discretise(j_min, j_max, C_res)`: lower, lower + C_res, … up to upper inclusive (List 2)."""
    count = int(np.floor((upper - lower) / resolution + 1e-9)) + 1
    return lower + resolution * np.arange(count)


def moore_offsets(dim: int) -> np.ndarray:
    """(b/2, dim): one of each ± pair of Moore neighbour offsets (first non-zero component positive)."""
    offsets = [d for d in itertools.product((-1, 0, 1), repeat=dim) if any(d) and next(x for x in d if x) > 0]
    return np.array(offsets, dtype=np.int64)


def moore_edges(shape: tuple[int, ...]) -> np.ndarray:
    """(|𝔈_C|, 2) node pairs of the non-wrapped Moore grid graph, each undirected edge once (row-major ids)."""
    index = np.arange(int(np.prod(shape)), dtype=np.int64).reshape(shape)
    blocks = []
    for d in moore_offsets(len(shape)):
        src = tuple(slice(max(0, -k), n - max(0, k)) for k, n in zip(d, shape, strict=True))
        dst = tuple(slice(max(0, k), n - max(0, -k)) for k, n in zip(d, shape, strict=True))
        blocks.append(np.stack([index[src].ravel(), index[dst].ravel()], axis=1))
    return np.concatenate(blocks)


def grid_edge_count(jv: int, dim: int = 2) -> int:
    """Closed form of the Moore grid's edges: eq. (7) for dim = 2, 4|jv|² − 6|jv| + 2; in general
    Σ over the ± pairs of offsets of Π (|jv| − |d_k|)."""
    return int(sum(np.prod([jv - abs(k) for k in d]) for d in moore_offsets(dim)))


def voxel_index(pos: np.ndarray, t_res: float) -> np.ndarray:
    """(N, dims) integer voxel coordinates, centroid = index·T_res: ‖pos − cent‖_∞ ≤ T_res/2 (line 11), a
    tie going to the centroid nearer the origin (the text's tie-break)."""
    x = pos / t_res
    return (np.sign(x) * np.ceil(np.abs(x) - 0.5)).astype(np.int64)


def voxel_box(voxel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The bounding box (lowest, highest integer coordinates) of a set of voxels."""
    return voxel.min(axis=0), voxel.max(axis=0)


def voxel_keys(voxel: np.ndarray, box: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """(N,) one integer per voxel, row-major over `box` (default: the bounding box of `voxel`), −1 for a voxel
    outside it: equal keys, equal voxels."""
    low, high = voxel_box(voxel) if box is None else box
    inside = ((voxel >= low) & (voxel <= high)).all(axis=1)
    keys = np.full(len(voxel), -1, dtype=np.int64)
    keys[inside] = np.ravel_multi_index(tuple((voxel[inside] - low).T), tuple(high - low + 1))
    return keys


@dataclass
class KinematicGraph:
    """The KG and what it was built from. Vertex arrays are indexed by c_idx."""

    arm: RegionalArm
    c_res: float                  # rad
    t_res: float                  # m
    axes: list[np.ndarray]        # joint values per joint (|jv| each)
    node_cluster: np.ndarray      # (|𝔙_C|,) c_idx of every C-grid node
    q: np.ndarray                 # (|𝔙_k|, n) C.q, eq. (9)
    pos: np.ndarray               # (|𝔙_k|, task_dims) C.pos, eq. (8)
    points: np.ndarray            # (|𝔙_k|, n + 2, 3) mean critical points (Sec. 3.3)
    voxel: np.ndarray             # (|𝔙_k|, task_dims) integer voxel coordinates; centroid = voxel·t_res
    members: np.ndarray           # (|𝔙_k|,) nodes per cluster
    edges: np.ndarray             # (|𝔈_k|, 2) c_idx pairs, lo < hi
    grid_edges: int               # |𝔈_C| counted
    occupied_voxels: int
    seconds: dict[str, float] = field(default_factory=dict)   # construction stages

    @property
    def jv(self) -> list[int]:
        return [len(a) for a in self.axes]

    @property
    def grid_nodes(self) -> int:
        return len(self.node_cluster)

    @property
    def size(self) -> int:
        return len(self.q)

    def manipulability(self) -> np.ndarray:
        return self.arm.manipulability(self.q)

    def clusters_per_voxel(self) -> np.ndarray:
        """(occupied voxels,) the number of clusters (KG vertices) in each occupied voxel."""
        _, counts = np.unique(voxel_keys(self.voxel), return_counts=True)
        return counts


@dataclass
class CGrid:
    """SampleConfigSpace and line 2 of Algorithm 1: the joint grid 𝔊_C, its nodes' FK and Moore edges."""

    axes: list[np.ndarray]   # joint values per joint (|jv| each)
    q: np.ndarray            # (|𝔙_C|, n) node configurations, row-major
    points: np.ndarray       # (|𝔙_C|, n + 2, 3) critical points; P_w last
    edges: np.ndarray        # (|𝔈_C|, 2)
    seconds: float           # sampling, FK and edges

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(a) for a in self.axes)


MAX_NODES = 4_000_000   # C-grid nodes one graph may have (memory: ~0.3 kB per node with its edges and FK)


def grid_nodes(arm: RegionalArm, c_res: float) -> int:
    """|𝔙_C| = Π |jv| of the joint grid at C_res, before building it."""
    return math.prod(len(joint_values(lo, hi, c_res)) for lo, hi in zip(arm.lower, arm.upper, strict=True))


def check_size(arm: RegionalArm, c_res: float) -> None:
    """Refuse a C_res whose grid would not fit in memory (ValueError), before anything is built."""
    if grid_nodes(arm, c_res) > MAX_NODES:
        raise ValueError(f"C_res = {math.degrees(c_res):g}° gives {grid_nodes(arm, c_res):,} C-grid nodes for "
                         f"{arm.name}, more than {MAX_NODES:,}: choose a coarser C_res")


def sample(arm: RegionalArm, c_res: float) -> CGrid:
    check_size(arm, c_res)
    start = time.perf_counter()
    axes = [joint_values(lo, hi, c_res) for lo, hi in zip(arm.lower, arm.upper, strict=True)]
    mesh = np.meshgrid(*axes, indexing="ij")
    q = np.stack([m.ravel() for m in mesh], axis=1)
    points = arm.points(q)
    edges = moore_edges(tuple(len(a) for a in axes))
    return CGrid(axes, q, points, edges, time.perf_counter() - start)


def _mean_by(labels: np.ndarray, values: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Per-label means of the rows of `values` (any trailing shape)."""
    flat = values.reshape(len(values), -1)
    sums = np.stack([np.bincount(labels, weights=flat[:, k], minlength=len(counts)) for k in range(flat.shape[1])],
                    axis=1)
    return (sums / counts[:, None]).reshape(len(counts), *values.shape[1:])


def build(arm: RegionalArm, c_res: float, t_res: float, grid: CGrid | None = None) -> KinematicGraph:
    """Algorithm 1 for `arm` at C_res (rad) and T_res (m); `grid` reuses a sampling at the same C_res."""
    grid = grid or sample(arm, c_res)
    seconds = {"sample_fk_edges": grid.seconds}
    start = time.perf_counter()
    pos = grid.points[:, -1, : arm.task_dims]
    voxel = voxel_index(pos, t_res)
    _, node_voxel = np.unique(voxel_keys(voxel), return_inverse=True)
    seconds["voxels"] = time.perf_counter() - start

    start = time.perf_counter()
    same = node_voxel[grid.edges[:, 0]] == node_voxel[grid.edges[:, 1]]
    inner = grid.edges[same]
    size = len(grid.q)
    inside = sparse.coo_matrix((np.ones(len(inner), dtype=np.int8), (inner[:, 0], inner[:, 1])),
                               shape=(size, size)).tocsr()
    count, cluster = connected_components(inside, directed=False)
    members = np.bincount(cluster, minlength=count)
    seconds["clusters"] = time.perf_counter() - start

    start = time.perf_counter()
    cluster = cluster.astype(np.int64)
    a, b = cluster[grid.edges[~same, 0]], cluster[grid.edges[~same, 1]]
    keys = np.unique(np.minimum(a, b) * count + np.maximum(a, b))
    edges = np.stack([keys // count, keys % count], axis=1)   # a cluster lies in one voxel: a != b here
    seconds["edges"] = time.perf_counter() - start

    start = time.perf_counter()
    first = np.zeros(count, dtype=np.int64)
    first[cluster[::-1]] = np.arange(size)[::-1]   # any member gives the cluster's voxel
    graph = KinematicGraph(
        arm=arm, c_res=c_res, t_res=t_res, axes=grid.axes, node_cluster=cluster,
        q=_mean_by(cluster, grid.q, members), pos=_mean_by(cluster, pos, members),
        points=_mean_by(cluster, grid.points, members), voxel=voxel[first], members=members, edges=edges,
        grid_edges=len(grid.edges), occupied_voxels=int(node_voxel.max()) + 1, seconds=seconds)
    seconds["attributes"] = time.perf_counter() - start
    return graph


def components(count: int, edges: np.ndarray) -> int:
    """Connected components of an undirected graph (the KG is connected if its C-grid is)."""
    matrix = sparse.coo_matrix((np.ones(len(edges), dtype=np.int8), (edges[:, 0], edges[:, 1])), shape=(count, count))
    return int(connected_components(matrix, directed=False)[0])


def adjacency(count: int, edges: np.ndarray) -> sparse.csr_matrix:
    """Symmetric CSR adjacency (data = 1) of an undirected edge list: the search's successor lists."""
    both = np.concatenate([edges, edges[:, ::-1]])
    matrix = sparse.coo_matrix((np.ones(len(both)), (both[:, 0], both[:, 1])), shape=(count, count)).tocsr()
    matrix.sort_indices()
    return matrix


@dataclass
class GridGraph:
    """The plain C-space grid graph 𝔊_C (the baseline): every node a vertex, Moore edges, node FK."""

    arm: RegionalArm
    c_res: float
    t_res: float
    axes: list[np.ndarray]
    q: np.ndarray            # (|𝔙_C|, n)
    pos: np.ndarray          # (|𝔙_C|, task_dims)
    points: np.ndarray       # (|𝔙_C|, n + 2, 3)
    voxel: np.ndarray        # (|𝔙_C|, task_dims) the node's voxel (the same goal test as the KG)
    edges: np.ndarray        # (|𝔈_C|, 2)

    @property
    def size(self) -> int:
        return len(self.q)

    def manipulability(self) -> np.ndarray:
        return self.arm.manipulability(self.q)


def grid_graph(arm: RegionalArm, c_res: float, t_res: float, grid: CGrid | None = None) -> GridGraph:
    grid = grid or sample(arm, c_res)
    pos = grid.points[:, -1, : arm.task_dims]
    return GridGraph(arm, c_res, t_res, grid.axes, grid.q, pos, grid.points, voxel_index(pos, t_res), grid.edges)
