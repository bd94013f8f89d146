"""The cost of one batched host query called from Python, per call and per point: a growbench algorithm
that grows nothing and measures instead (bench/scene_query_bench.cpp's BM_ClosestPointsBatch is the same
call from C++). Its figures are the trial's algorithm_stats:

    growbench run --plugin bench/python/query_cost.py --algorithm query_cost \\
        --scene mesh:stanford-bunny --out out/query_cost
"""
import time

import numpy as np

import growbench


class QueryCost:
    name = "query_cost"
    summary = "times batched host queries from Python (grows one node per seed)"
    version = "1"
    params = [growbench.real("seconds", 0.5, min=0.01, max=60, unit="s", doc="time spent per batch size")]

    def start(self, scene, host, params, seed):
        lo, hi = np.array(scene.bounds_min), np.array(scene.bounds_max)
        u = host.uniform(seed, np.arange(3 * 1024, dtype=np.uint64)).reshape(-1, 3)
        pts = (lo - 0.1 * (hi - lo) + u * 1.2 * (hi - lo)).astype(np.float32)
        self.figures = {}
        # Unbounded (the search itself dominates) and within 5 cm (cheap, so the crossing shows).
        for bound, radius in (("unbounded", np.inf), ("bounded", 0.05)):
            for n in (1, 1024):
                batch = np.ascontiguousarray(pts[:n])
                calls, t0 = 0, time.perf_counter()
                while time.perf_counter() - t0 < params["seconds"]:
                    host.closest_points(batch, radius)
                    calls += 1
                per_call = (time.perf_counter() - t0) / calls
                self.figures[f"closest_points_{bound}_{n}_us_per_call"] = per_call * 1e6
                self.figures[f"closest_points_{bound}_{n}_ns_per_point"] = per_call / n * 1e9
        self.seeds = np.asarray(scene.seed_positions, dtype=np.float32)

    def step(self):
        return False

    def plant(self):
        return {"positions": self.seeds, "parent": np.full(len(self.seeds), -1)}

    def stats(self):
        return self.figures


PLUGIN = QueryCost
