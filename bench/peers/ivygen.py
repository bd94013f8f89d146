# The Blender IvyGen peer of `make peers`: grows the add-on's ivy headless and prints one JSON line.
#   blender -b --factory-startup --python ivygen.py -- MESH.obj --seed X,Y,Z --max-ivy-length L
# MESH.obj and the seed are in growbench's axes (OBJ's, Y up); Blender's are Z up, so both are turned
# by (x, y, z) -> (x, -z, y), the mapping of Blender's own OBJ importer, and gravity points the same
# way in both programs. Every other IvyGen setting stays at the add-on's default (the panel's
# properties), as a user who only sets maxIvyLength gets.
import argparse
import json
import sys
import time

import addon_utils
import bpy


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="ivygen.py")
    p.add_argument("mesh")
    p.add_argument("--seed", required=True, help="X,Y,Z in the OBJ's axes")
    p.add_argument("--max-ivy-length", type=float, required=True)
    p.add_argument("--random-seed", type=int, default=0)
    p.add_argument("--no-geometry", dest="geometry", action="store_false",
                   help="skip IvyGen's curve and leaves (growth does not depend on them; operator_s is then growth alone)")
    return p.parse_args(argv)


def to_blender(x, y, z):
    return (x, -z, y)


def read_obj(path):
    verts, faces = [], []
    with open(path) as f:
        for line in f:
            w = line.split()
            if not w or w[0] not in ("v", "f"):
                continue
            if w[0] == "v":
                verts.append(to_blender(*map(float, w[1:4])))
            else:
                faces.append([int(t.split("/")[0]) - 1 for t in w[1:]])
    return verts, faces


def make_active_mesh(path):
    # --factory-startup brings the default cube, camera and light: remove them so only our mesh exists.
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    verts, faces = read_obj(path)
    mesh = bpy.data.meshes.new("peer_mesh")
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    ob = bpy.data.objects.new("peer_mesh", mesh)
    bpy.context.scene.collection.objects.link(ob)
    bpy.context.view_layer.objects.active = ob
    ob.select_set(True)


def main():
    args = parse_args()
    addon_utils.enable("add_curve_ivygen", default_set=True)
    ivygen = sys.modules["add_curve_ivygen"]
    make_active_mesh(args.mesh)
    bpy.context.scene.cursor.location = to_blender(*map(float, args.seed.split(",")))
    props = bpy.context.window_manager.ivy_gen_props
    props.maxIvyLength = args.max_ivy_length
    props.randomSeed = args.random_seed

    # The operator keeps its Ivy object local and goes straight on to build the curve and leaf mesh.
    # Wrapping the module's functions (looked up at call time) marks where growth starts (after the BVH
    # of the mesh is built, growbench's scene load) and ends (when createIvyGeometry is handed the Ivy
    # object), so growth alone is compared with growbench's growth phase, and the nodes are counted
    # from the add-on's own data.
    seen = {}
    build_geometry = ivygen.createIvyGeometry
    build_bvh = ivygen.bvhtree_from_object

    def timed_bvh(ob):
        tree = build_bvh(ob)
        seen["growth_from"] = time.perf_counter()
        seen["cpu_from"] = time.process_time()
        return tree

    # The curve and leaves are what a user waits for too (operator_s), but not growth ("seconds"); they take
    # longer than growth, so --no-geometry skips them when only growth is wanted.
    def counted(ivy, grow_leaves):
        t = time.perf_counter()
        seen["grown_at"] = t
        seen["cpu_at"] = time.process_time()
        seen["roots"] = len(ivy.ivyRoots)
        seen["stored"] = sum(len(r.ivyNodes) for r in ivy.ivyRoots)
        if args.geometry:
            build_geometry(ivy, grow_leaves)
        seen["geometry_s"] = time.perf_counter() - t

    ivygen.createIvyGeometry = counted
    ivygen.bvhtree_from_object = timed_bvh
    t0, c0 = time.perf_counter(), time.process_time()
    result = bpy.ops.curve.ivy_gen(updateIvy=True)
    total, total_cpu = time.perf_counter() - t0, time.process_time() - c0
    if result != {"FINISHED"} or "stored" not in seen:
        print("ivygen.py: the IvyGen operator did not finish: %s" % (result,), file=sys.stderr)
        sys.exit(1)
    # A branch root's first node is a copy of its parent's node (IvyGen's Ivy.grow); growbench starts a
    # branch at the parent's node itself, so the copies are left out of the node count compared.
    nodes = seen["stored"] - (seen["roots"] - 1)
    print(json.dumps({
        "peer": "blender-ivygen",
        "blender": bpy.app.version_string,
        "addon": ".".join(map(str, ivygen.bl_info["version"])),
        "seconds": seen["grown_at"] - seen["growth_from"],
        "cpu_seconds": seen["cpu_at"] - seen["cpu_from"],
        "operator_s": total,
        "geometry_s": seen["geometry_s"] if args.geometry else None,
        "operator_cpu_s": total_cpu,
        "nodes": nodes,
        "stored_nodes": seen["stored"],
        "roots": seen["roots"],
    }))
    sys.stdout.flush()


main()
