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
    s = time_calls("ours", lambda T: ik.solve(T, g), [(T,) for T in poses], warmup=200).summary_us()
    rows.append({"what": "ik_all, Λ degree 16 (ours, numba)", "measure": "per pose, median (p95)",
                 "value": s["median_us"], "p95": s["p95_us"], "unit": "µs", "goal": "≤ 100", "paper": "not reported"})
    chunks = [(poses[i:i + CHUNK],) for i in range(0, POSES, CHUNK)]
    s = time_calls("ours_batch", lambda P: ik.solve_batch(P, g), chunks, warmup=1, repeats=3,
                   items_per_call=CHUNK).summary_us()
    rows.append({"what": f"ik_batch ({CHUNK} poses per call, ours)", "measure": "per pose, median (p95)",
                 "value": s["median_us"], "p95": s["p95_us"], "unit": "µs", "goal": "≤ 20", "paper": "not reported"})
    ours = [ik.solve(T, g) for T in poses]
    for peer in peers.all_peers(g, starts=50):
        if not peer.available:
            rows.append({"what": peer.label, "measure": peer.reason, "value": float("nan"), "unit": ""})
            continue
        n = POSES if peer.name == "crx" else SLOW_POSES
        inputs = [(peer.prepare(T),) for T in poses[:n]]
        s = time_calls(peer.name, peer.call, inputs, warmup=min(200, n)).summary_us()
        stats = np.array([peers.compare(o, peer.convert(peer.call(x)), peer.match_tol)
                          for o, (x,) in zip(ours[:n], inputs, strict=False)]).sum(axis=0)
        rows.append({"what": peer.label, "measure": f"per pose, median (p95); vs ours on {n} poses: {stats[0]} common, "
                     f"{stats[1]} ours only, {stats[2]} peer only", "value": s["median_us"], "p95": s["p95_us"],
                     "unit": "µs"})
    return rows
