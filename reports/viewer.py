"""The report's 3D viewer: what each trial page needs to turn its plant around on its scene and play its growth.

A page opened from file:// can load neither an ES module nor a file through fetch (Chromium refuses both for
the page's "null" origin), so everything arrives as classic scripts:
    REPORT/viewer/growbench-viewer.js   three.js and the viewer in one script (tools/viewer, built by
                                        scripts/install-deps), once per report, with its THIRD-PARTY.txt
    REPORT/scenes/NAME-HASH.glb.js      each scene's scene.glb once, gzipped, as base64 (the results' "scenes" map)
    REPORT/trials/SLUG/plant.glb.js     the trial's plant.glb, gzipped, as base64
The viewer (tools/viewer/src/viewer.js) turns each <div class='gb-viewer'> into a canvas; growth playback reads
the _BIRTH_STEP each vertex and organ instance of plant.glb carries.
"""

import base64
import gzip
import html
import json
import os
import shutil
import sys

DIST = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools", "viewer", "dist")
BUNDLE = "growbench-viewer.js"
NOTICE = "THIRD-PARTY.txt"


def write_data_script(src, dst, key):
    """SRC's bytes, gzipped, as base64 in a classic script that files them under KEY in self.GB_DATA; its size.
    A meshopt-compressed GLB still shrinks by about 40% under gzip, which browsers undo natively
    (DecompressionStream): the base64 costs 4/3, the gzip gives more than that back."""
    with open(src, "rb") as f:
        data = base64.b64encode(gzip.compress(f.read(), compresslevel=6, mtime=0))
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    with open(dst, "wb") as f:
        # json.dumps makes any key a valid JavaScript string literal.
        f.write(b"(self.GB_DATA=self.GB_DATA||{})[" + json.dumps(key).encode() + b']="' + data + b'";\n')
    return os.path.getsize(dst)


def copy_bundle(out):
    """The viewer's script into OUT/viewer/; False (with a warning) when it was never built."""
    if not os.path.isfile(os.path.join(DIST, BUNDLE)):
        print(f"report: warning: {os.path.normpath(os.path.join(DIST, BUNDLE))} is missing (scripts/install-deps builds "
              "it); the trial pages have no 3D view", file=sys.stderr)
        return False
    os.makedirs(os.path.join(out, "viewer"), exist_ok=True)
    for f in (BUNDLE, NOTICE):
        if os.path.isfile(os.path.join(DIST, f)):
            shutil.copyfile(os.path.join(DIST, f), os.path.join(out, "viewer", f))
    return True


def scene_scripts(doc, base, out, own_path, slug):
    """Each scene.glb the results name ("scenes": {hash: path}), once, as OUT/scenes/NAME-HASH.glb.js;
    {hash: (path relative to OUT, key)}."""
    done = {}
    for h, name in sorted((doc.get("scenes") or {}).items()):
        src = own_path(base, name)
        if src is None or not os.path.isfile(src):
            print(f"report: warning: scene file {name!r} is not a file inside {base}; its plants are shown alone",
                  file=sys.stderr)
            continue
        rel = f"scenes/{slug(os.path.basename(name))}.js"
        write_data_script(src, os.path.join(out, rel), f"scene:{h}")
        done[h] = (rel, f"scene:{h}")
    return done


def write_assets(doc, cells, base, out, own_path, slug, trial_dir_of, autoload_mb):
    """The viewer, the scenes and each trial's plant as scripts under OUT; {trial id: the page's viewer HTML
    (or a sentence saying why there is none)}. None when the viewer is not built."""
    if not copy_bundle(out):
        return None
    scenes = scene_scripts(doc, base, out, own_path, slug)
    views, written = {}, 0
    for c in cells:
        d = trial_dir_of(c, base)
        glb = os.path.join(d, "plant.glb") if d else None
        if not d:
            views[c.id()] = ("<p class='note'>No 3D view: the trial's folder is not beside the results file (a merged "
                             "file names its shards' trials in their own folders).</p>")
            continue
        if not os.path.isfile(glb):
            views[c.id()] = "<p class='note'>No 3D view: the trial left no plant.glb.</p>"
            continue
        rel = f"{slug(c.id())}/plant.glb.js"
        written += write_data_script(glb, os.path.join(out, "trials", rel), f"plant:{c.id()}")
        views[c.id()] = viewer_html(rel, f"plant:{c.id()}", os.path.getsize(glb), scenes.get(c.t.get("scene_hash")),
                                    autoload_mb)
    print(f"report: 3D views of {sum(1 for v in views.values() if 'gb-viewer' in v)} plants on {len(scenes)} scenes: "
          f"{written / 1e6:.1f} MB of plant data", file=sys.stderr)
    return views


def viewer_html(plant, key, size, scene, autoload_mb):
    """The element the viewer script turns into a 3D view, for a page in OUT/trials/, and its caption."""
    e = html.escape
    attrs = {"data-plant": plant, "data-plant-key": key, "data-plant-bytes": str(size),
             "data-autoload": "true" if size <= autoload_mb * 1e6 else "false"}
    if scene:
        attrs |= {"data-scene": "../" + scene[0], "data-scene-key": scene[1]}
    div = "<div class='gb-viewer' " + " ".join(f"{k}='{e(v)}'" for k, v in attrs.items()) + "></div>"
    where = "on its scene" if scene else "alone (the results name no scene.glb for its scene)"
    return (f"<h2>3D view</h2>{div}<p class='note'>plant.glb ({size / 1e6:.2f} MB) {where}. Drag to orbit, wheel to "
            "zoom, right-drag to pan. Playback: the frame at step k shows every node born at step k or before, "
            "with its organs, at their final radius and place.</p><script src='../viewer/growbench-viewer.js'></script>")
