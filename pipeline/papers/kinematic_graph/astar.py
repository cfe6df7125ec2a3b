"""The compiled A* of `search` (Numba): a binary heap of (f, vertex) on arrays over CSR successor lists, and the
metrics' heuristics. Its own module so that only the experiments that search load Numba (0.13 s to import): the graph
experiment (table1) builds graphs and never searches them.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def heuristic(code, v, q, pos, weight, q_goal, goal, diagonal, w_min):  # pragma: no cover - compiled
    """h at vertex v for the metric numbered `code` (`search.METRICS` order; < 0: none, which is Dijkstra)."""
    if code < 0:                                    # none: Dijkstra
        return 0.0
    if code == 0:                                   # cspace: ‖q_goal − C.q‖
        s = 0.0
        for j in range(q.shape[1]):
            s += (q_goal[j] - q[v, j]) ** 2
        return np.sqrt(s)
    s = 0.0
    for j in range(pos.shape[1]):
        s += (goal[j] - pos[v, j]) ** 2
    if code == 1:                                   # tspace: ‖P_w,g − C.pos‖
        return np.sqrt(s)
    if code == 2:                                   # eq. (12): ‖P_w,g − C.pos‖² (μ_max − μ(C.q))
        return s * weight[v]
    return max(np.sqrt(s) - diagonal, 0.0) * w_min  # the admissible bound


@njit(cache=True)
def _push(keys, items, size, key, item):  # pragma: no cover - compiled
    """Binary min-heap on parallel arrays (grown by the caller): sift `key` up from position `size`."""
    i = size
    while i > 0:
        up = (i - 1) >> 1
        if keys[up] <= key:
            break
        keys[i], items[i] = keys[up], items[up]
        i = up
    keys[i], items[i] = key, item


@njit(cache=True)
def _pop(keys, items, size):  # pragma: no cover - compiled
    """Remove the root of a heap of `size` entries; returns it (key, item)."""
    key, item = keys[0], items[0]
    last_key, last_item = keys[size - 1], items[size - 1]
    size -= 1
    i = 0
    while True:
        child = 2 * i + 1
        if child >= size:
            break
        if child + 1 < size and keys[child + 1] < keys[child]:
            child += 1
        if keys[child] >= last_key:
            break
        keys[i], items[i] = keys[child], items[child]
        i = child
    if size > 0:
        keys[i], items[i] = last_key, last_item
    return key, item


@njit(cache=True)
def astar(indptr, indices, costs, blocked, goal_mask, start, limit, code, q, pos, weight, q_goal, goal, diagonal,
          w_min):  # pragma: no cover - compiled
    """A* from `start` to the first goal vertex popped; the heuristic is evaluated when a vertex is first met.
    Returns (reached goal, −1 if none is connected, −2 if `limit` expansions did not reach it; g, parent,
    expanded, met, expansions): g and parent per vertex; expanded marks the vertices expanded at least once
    (green in Fig. 5), met those ever queued (green + yellow); expansions counts every expansion, re-openings
    included (an inconsistent heuristic can make them exponential, hence the limit)."""
    n = len(blocked)
    g = np.full(n, np.inf)
    h = np.full(n, np.nan)
    parent = np.full(n, -1, dtype=np.int64)
    closed = np.zeros(n, dtype=np.bool_)
    expanded = np.zeros(n, dtype=np.bool_)
    met = np.zeros(n, dtype=np.bool_)
    keys = np.empty(1024)
    items = np.empty(1024, dtype=np.int64)
    g[start] = 0.0
    met[start] = True
    h[start] = heuristic(code, start, q, pos, weight, q_goal, goal, diagonal, w_min)
    _push(keys, items, 0, h[start], start)
    size = 1
    expansions = 0
    while size > 0:
        f, u = _pop(keys, items, size)
        size -= 1
        if closed[u] or f > g[u] + h[u]:
            continue   # stale entry
        if goal_mask[u]:
            return u, g, parent, expanded, met, expansions
        if expansions == limit:
            return -2, g, parent, expanded, met, expansions
        closed[u] = True
        expanded[u] = True
        expansions += 1
        for k in range(indptr[u], indptr[u + 1]):
            v = indices[k]
            if blocked[v]:
                continue
            cand = g[u] + costs[k]
            if cand < g[v]:
                if not met[v]:
                    met[v] = True
                    h[v] = heuristic(code, v, q, pos, weight, q_goal, goal, diagonal, w_min)
                g[v] = cand
                parent[v] = u
                closed[v] = False   # re-open: an inconsistent heuristic may close a vertex too early
                if size == len(keys):
                    keys = np.concatenate((keys, np.empty(size)))
                    items = np.concatenate((items, np.empty(size, dtype=np.int64)))
                _push(keys, items, size, cand + h[v], v)
                size += 1
    return -1, g, parent, expanded, met, expansions
