"""Space colonization (Runions et al. 2007) in numpy: a growbench algorithm written in Python.

    growbench run --plugin examples/python/spacecol.py --algorithm spacecol_py --scene envelope
    growbench plugin-test examples/python/spacecol.py

Attraction points fill the scene's envelope (or the space above its surfaces); each step, every point
pulls the node nearest to it within `influence`, each pulled node grows one `step` towards the mean
direction of its points, and points within `kill` of the plant are used up. The host's queries keep
new nodes out of solids. Tips bear blossoms (the built-in shape), branches are coloured from bark to
young green, and every node carries its `depth` from the root. docs/plugins.md, "Algorithms in
Python", explains each part.
"""
import numpy as np

import growbench


class SpaceColonization:
    name = "spacecol_py"
    summary = "space colonization in numpy: attraction points pull the nearest nodes (a Python example)"
    version = "1.0"
    params = [
        growbench.integer("point_count", 10000, min=1, max=10_000_000, doc="attraction points"),
        growbench.real("influence", 0.2, min=1e-4, max=100, unit="m", doc="a point pulls nodes this near"),
        growbench.real("kill", 0.04, min=1e-5, max=100, unit="m", doc="a point is used up this near a node"),
        growbench.real("step", 0.02, min=1e-5, max=10, unit="m", doc="length of one new segment"),
        growbench.real("tip_radius", 0.002, min=1e-6, max=1, unit="m", doc="radius of branch tips (pipe model)"),
        growbench.boolean("blossoms", True, doc="branch tips bear blossoms"),
    ]
    test_params = ["point_count=800"]

    def start(self, scene, host, params, seed):
        self.host, self.p = host, params
        if len(scene.seed_positions) == 0:
            raise growbench.InputError("algorithm 'spacecol_py': the scene has no seeds")
        self.points = self.attraction_points(scene, seed)
        self.positions = np.array(scene.seed_positions, dtype=np.float32)
        self.parent = np.full(len(self.positions), -1, dtype=np.int64)
        self.birth = np.zeros(len(self.positions), dtype=np.int64)
        self.steps = 0
        self.grown_before = set()  # (parent, x, y, z) of every node grown
        self.near_d = np.full(len(self.points), np.inf, dtype=np.float32)
        self.near_i = np.zeros(len(self.points), dtype=np.int64)
        self.update_nearest(0)

    def attraction_points(self, scene, seed):
        """Uniform in the envelope (or the box of the scene's surfaces and seeds), outside every solid."""
        lo = np.array(scene.envelope_min if scene.has_envelope else scene.bounds_min, dtype=np.float64)
        hi = np.array(scene.envelope_max if scene.has_envelope else scene.bounds_max, dtype=np.float64)
        seeds = np.asarray(scene.seed_positions, dtype=np.float64)
        lo, hi = np.minimum(lo, seeds.min(axis=0)), np.maximum(hi, seeds.max(axis=0) + [0, 0.5, 0])
        n = self.p["point_count"]
        counters = np.arange(3 * n, dtype=np.uint64)
        u = self.host.uniform(seed, counters).reshape(n, 3)
        pts = (lo + u * (hi - lo)).astype(np.float32)
        keep = ~self.host.inside(pts)
        if scene.has_envelope:
            keep &= self.host.inside_shape(growbench.ENVELOPE, pts)
        return pts[keep]

    def step(self):
        if len(self.points) == 0 or self.host.cancelled():
            return False
        pulling = self.near_d < self.p["influence"]
        if not pulling.any():  # no point in reach yet: the trunk grows towards the nearest point
            pulling = np.arange(len(self.points)) == self.near_d.argmin()
        # Each pulled node grows towards the mean of the unit vectors to its points (np.add.at: in order).
        owner = self.near_i[pulling]
        to_point = self.points[pulling] - self.positions[owner]
        to_point /= np.maximum(np.linalg.norm(to_point, axis=1, keepdims=True), 1e-12)
        pull = np.zeros_like(self.positions)
        np.add.at(pull, owner, to_point)
        count = np.bincount(owner, minlength=len(self.positions))
        grown = np.unique(owner)
        length = np.linalg.norm(pull[grown], axis=1)
        grown, length = grown[length > 0.05 * count[grown]], length[length > 0.05 * count[grown]]  # not torn apart
        new = (self.positions[grown] + self.p["step"] * pull[grown] / length[:, None]).astype(np.float32)
        ok = ~self.host.inside(new)  # never into a solid
        keys = [(int(g), *map(float, x)) for g, x in zip(grown, new)]
        seen = np.array([k in self.grown_before for k in keys], dtype=bool)
        stuck = grown[seen]
        ok &= ~seen
        self.grown_before.update(k for k, good in zip(keys, ok) if good)
        if not ok.any() and len(stuck) == 0:
            return False
        self.steps += 1
        first = len(self.positions)
        self.positions = np.concatenate([self.positions, new[ok]])
        self.parent = np.concatenate([self.parent, grown[ok]])
        self.birth = np.concatenate([self.birth, np.full(ok.sum(), self.steps)])
        self.update_nearest(first)
        # Used up: the points the plant reached, and those pulling a node that would grow a child it has already
        # grown (points on either side of a node hold it in place: it would grow the same child forever).
        keep = (self.near_d >= self.p["kill"]) & ~np.isin(self.near_i, stuck)
        self.points, self.near_d, self.near_i = self.points[keep], self.near_d[keep], self.near_i[keep]
        return True

    def update_nearest(self, first):
        """Each point's nearest node among those from `first` on, where nearer than its nearest so far (a tie
        keeps the older node, as a search over all nodes in order would): nodes never move, so only the new
        ones are searched."""
        new = self.positions[first:]
        if len(new) == 0:
            return
        for a in range(0, len(self.points), 4096):
            d = np.linalg.norm(self.points[a:a + 4096, None, :] - new[None, :, :], axis=2)
            k = d.argmin(axis=1)
            dk = d[np.arange(len(d)), k]
            closer = dk < self.near_d[a:a + 4096]
            self.near_d[a:a + 4096][closer] = dk[closer]
            self.near_i[a:a + 4096][closer] = first + k[closer]

    def finish(self):
        n = len(self.positions)
        children = np.bincount(self.parent[self.parent >= 0], minlength=n)
        # Pipe model (r^2 = sum of the children's r^2): children follow their parents, so one backward pass.
        r2 = np.zeros(n)
        for i in range(n - 1, -1, -1):
            r2[i] = r2[i] if r2[i] > 0 else self.p["tip_radius"] ** 2
            if self.parent[i] >= 0:
                r2[self.parent[i]] += r2[i]
        self.radius = np.sqrt(r2).astype(np.float32)
        self.depth = np.zeros(n, dtype=np.float32)
        for i in range(n):
            if self.parent[i] >= 0:
                self.depth[i] = self.depth[self.parent[i]] + 1
        self.tips = np.flatnonzero((children == 0) & (self.parent >= 0))

    def plant(self):
        n = len(self.positions)
        out = {"positions": self.positions, "parent": self.parent, "birth_step": self.birth,
               "radius": getattr(self, "radius", np.full(n, self.p["tip_radius"], dtype=np.float32))}
        if not hasattr(self, "tips"):
            return out
        young = self.birth / max(self.steps, 1)  # 0 at the root, 1 at the newest node
        out["attributes"] = {
            "Cd": np.stack([0.30 - 0.15 * young, 0.20 + 0.25 * young, np.full(n, 0.08)], axis=1),
            "depth": self.depth,
        }
        tips = self.tips
        out["organ_positions"] = self.positions[tips]
        out["organ_nodes"] = tips
        out["organ_sizes"] = np.full(len(tips), 0.03, dtype=np.float32)
        out["organ_orientations"] = self.orientations(tips)
        if self.p["blossoms"]:
            out["organ_kinds"] = np.full(len(tips), growbench.FLOWER)
            out["organ_shapes"] = ["blossom"]
            out["organ_shape"] = np.zeros(len(tips), dtype=np.uint16)
            out["organ_tint"] = np.stack([np.ones(len(tips)), 0.8 + 0.2 * (tips % 2), np.full(len(tips), 0.9)], axis=1)
        return out

    def orientations(self, tips):
        """Unit quaternions (w, x, y, z) turning +Z onto each tip's segment direction."""
        d = self.positions[tips] - self.positions[self.parent[tips]]
        d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
        z = np.array([0.0, 0.0, 1.0])
        axis = np.cross(np.broadcast_to(z, d.shape), d)
        w = 1.0 + d @ z
        q = np.concatenate([w[:, None], axis], axis=1)
        flipped = w < 1e-6  # pointing down -Z: half a turn about X
        q[flipped] = [0.0, 1.0, 0.0, 0.0]
        return (q / np.linalg.norm(q, axis=1, keepdims=True)).astype(np.float32)

    def counts(self):
        """(nodes, organs), read after every step: cheaper than building the plant dict."""
        return len(self.positions), len(self.tips) if hasattr(self, "tips") else 0

    def stats(self):
        return {"points_left": float(len(self.points))}


PLUGIN = SpaceColonization
