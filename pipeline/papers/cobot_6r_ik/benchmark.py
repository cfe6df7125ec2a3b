"""Speed of `cobot-6r-ik`: all IK solutions per pose, scalar and batched, beside the peers of the [bench]
extra timed in the same run (`pip install -e '.[bench]'`), with how their solution sets compare with ours."""

from __future__ import annotations

import numpy as np

from pipeline.core.timing import time_calls
from pipeline.papers.cobot_6r_ik import ik, peers
from pipeline.papers.cobot_6r_ik.experiments import random_joints
from pipeline.papers.cobot_6r_ik.kinematics import CRX10IAL, fk

POSES = 2000
CHUNK = 10
SLOW_POSES = 20   # for the general-6R and numerical peers (tens of ms per pose)


def benchmark() -> list[dict]:
    g = CRX10IAL
    poses = fk(random_joints(np.random.default_rng(0), POSES), g)
    rows = []
    chunks = [(poses[i:i + CHUNK],) for i in range(0, POSES, CHUNK)]
    for method, label in (("lambda16", "the paper's Λ, degree 16"), ("octic", "Λ's genuine octic")):
        scalar = time_calls(method, lambda T, m=method: ik.solve(T, g, method=m), [(T,) for T in poses],
                            warmup=200).summary_us()
        batch = time_calls(method, lambda P, m=method: ik.solve_batch(P, g, method=m), chunks, warmup=1,
                           repeats=3, items_per_call=CHUNK).summary_us()
        for what, s, goal in ((f"ik_all, {label} (ours, numba)", scalar, "≤ 100"),
                              (f"ik_batch, {label} ({CHUNK} poses per call, ours)", batch, "≤ 20")):
            rows.append({"what": what, "measure": "per pose, median (p95)", "value": s["median_us"],
                         "p95": s["p95_us"], "unit": "µs", "goal": goal, "paper": "not reported"})
    ours = [ik.solve(T, g, method="octic") for T in poses]
    for peer in peers.all_peers(g, starts=50):
        if not peer.available:
            rows.append({"what": peer.label, "measure": peer.reason, "value": float("nan"), "unit": ""})
            continue
        n = POSES if peer.name == "crx" else SLOW_POSES
        inputs = [(peer.prepare(T),) for T in poses[:n]]
        s = time_calls(peer.name, peer.call, inputs, warmup=min(200, n)).summary_us()
        common, ours_only, peer_only = np.array([peers.compare(o, peer.convert(peer.call(x)), peer.match_tol)
                                                 for o, (x,) in zip(ours[:n], inputs, strict=False)]).sum(axis=0)
        rows.append({"what": peer.label, "measure": f"per pose, median (p95); vs our octic on {n} poses: {common} "
                     f"common, {ours_only} ours only, {peer_only} peer only", "value": s["median_us"],
                     "p95": s["p95_us"], "unit": "µs"})
    return rows
