// growbench's report viewer: a plant.glb on its scene.glb, orbit and zoom, the scene's light, toggles for the
// plant's parts, and growth playback from each vertex's and organ instance's _BIRTH_STEP.
//
// Bundled by build.mjs (esbuild) into ONE classic script, dist/growbench-viewer.js, because Chromium refuses
// ES module imports over file:// (a module script is fetched in CORS mode, and a file:// page's origin is
// "null"). For the same reason the viewer never fetches a .glb: each data file is a classic script,
// FILE.glb.js, holding the GLB (gzipped or not) as base64: `(self.GB_DATA = self.GB_DATA || {})["KEY"] = "...";`.
// The viewer adds a <script> for it, then decodes, unzips and parses it with GLTFLoader.parse.
//
// A page holds one element per viewer and loads this script after it:
//   <div class="gb-viewer" data-plant="ID/plant.glb.js" data-plant-key="plant:ID"
//        data-scene="../scenes/wall-fd46c4b06c5f885f.glb.js" data-scene-key="scene:fd46c4b06c5f885f"
//        data-plant-bytes="1459648" data-autoload="true"></div>
//   <script src="../viewer/growbench-viewer.js"></script>
// data-autoload="false" shows a button with the plant's size instead of loading it at once.
//
// Playback: frame k shows every vertex and organ instance whose _BIRTH_STEP <= k. Each primitive's
// triangles (or lines) are sorted once by the largest birth step of their vertices, and each instanced
// organ shape's instances by theirs, so a frame is a draw range (or instance count): no per-frame data.
//
// For tests: <body data-viewer="loading|loaded|error">, and window.GBViewer.viewers[i].stats().
import {
  AmbientLight, Box3, Color, DirectionalLight, HemisphereLight, PerspectiveCamera, Scene, Sphere, Vector3, WebGLRenderer,
} from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const CSS = `
.gb-viewer { position: relative; max-width: 1000px; border: 1px solid #ccc; background: #eef1f4; font: 13px DejaVu Sans, sans-serif; }
.gb-viewer canvas { display: block; width: 100%; touch-action: none; }
.gb-viewer .gb-bar { display: flex; flex-wrap: wrap; gap: 0.4em 1em; align-items: center; padding: 0.4em 0.6em; background: #fff; border-top: 1px solid #ddd; }
.gb-viewer .gb-bar label { white-space: nowrap; }
.gb-viewer .gb-bar input[type=range] { flex: 1 1 200px; }
.gb-viewer .gb-step { min-width: 11em; font-variant-numeric: tabular-nums; }
.gb-viewer .gb-status { position: absolute; left: 0.6em; top: 0.4em; color: #333; background: rgba(255,255,255,0.8); padding: 0 0.3em; }
.gb-viewer .gb-status.error { color: #c00; font-weight: bold; }
.gb-viewer .gb-load { position: absolute; left: 50%; top: 40%; transform: translate(-50%, -50%); font-size: 1.1em; padding: 0.5em 1em; }
`;
const PARTS = ['branches', 'leaves', 'flowers'];
const PART_OF_MATERIAL = { bark: 'branches', leaf: 'leaves', flower: 'flowers' };

let bodyState = {};  // viewer index -> state, summarised on <body data-viewer>
function setBodyState(i, state) {
  bodyState[i] = state;
  const all = Object.values(bodyState);
  // 'deferred': a plant over the autoload size, waiting for its button.
  document.body.dataset.viewer = all.includes('error') ? 'error' : all.includes('loading') ? 'loading'
    : all.includes('deferred') ? 'deferred' : 'loaded';
}

// The bytes of a data script: add <script src>, then take its base64 out of GB_DATA.
function loadData(src, key) {
  return new Promise((resolve, reject) => {
    const s = document.createElement('script');
    s.src = src;
    s.onload = () => {
      const text = self.GB_DATA && self.GB_DATA[key];
      if (typeof text !== 'string') return reject(new Error(`${src} did not define GB_DATA["${key}"]`));
      delete self.GB_DATA[key];
      s.remove();
      resolve(gunzipped(decodeBase64(text)));
    };
    s.onerror = () => reject(new Error(`cannot load ${src}`));
    document.head.appendChild(s);
  });
}
// The bytes themselves, or, when they are gzipped (the report gzips each .glb: 1f 8b, where a GLB starts
// "glTF"), what they unzip to.
function gunzipped(bytes) {
  if (bytes[0] !== 0x1f || bytes[1] !== 0x8b) return Promise.resolve(bytes.buffer);
  return new Response(new Blob([bytes]).stream().pipeThrough(new DecompressionStream('gzip'))).arrayBuffer();
}
function decodeBase64(text) {
  if (Uint8Array.fromBase64) return Uint8Array.fromBase64(text);
  const bin = atob(text), out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}
function parseGlb(buffer) {
  const loader = new GLTFLoader();
  loader.setMeshoptDecoder(MeshoptDecoder);
  return new Promise((resolve, reject) => loader.parse(buffer, '', resolve, reject));
}

// The part (branches, leaves, flowers) of a plant mesh: its material's name (every layout names the
// materials bark, leaf and flower; polygons wear leaf), else the nearest ancestor named as a part.
function partOf(object) {
  const m = Array.isArray(object.material) ? object.material[0] : object.material;
  if (m && PART_OF_MATERIAL[m.name]) return PART_OF_MATERIAL[m.name];
  for (let o = object; o; o = o.parent) if (PARTS.includes(o.name)) return o.name;
  return 'branches';
}

// Sorts a mesh's primitives (or instances) by birth step; returns the prefix counts by step, or null when
// the mesh has no _BIRTH_STEP.
function prepareGrowth(mesh, lastStep) {
  const g = mesh.geometry;
  if (mesh.isInstancedMesh) {
    const a = g.attributes._BIRTH_STEP;
    if (!a) return null;
    // getX, not .array: a step may be a uint16 in a 4-byte record (an interleaved attribute).
    const n = mesh.count, srcSteps = Float64Array.from({ length: n }, (_, i) => a.getX(i));
    const order = countingOrder(n, i => srcSteps[i], lastStep);
    const src = mesh.instanceMatrix.array.slice(), dst = mesh.instanceMatrix.array;
    const colors = mesh.instanceColor ? mesh.instanceColor.array.slice() : null;
    for (let j = 0; j < n; j++) {
      const i = order.items[j];
      dst.set(src.subarray(16 * i, 16 * i + 16), 16 * j);
      a.setX(j, srcSteps[i]);
      if (colors) mesh.instanceColor.array.set(colors.subarray(3 * i, 3 * i + 3), 3 * j);
    }
    mesh.instanceMatrix.needsUpdate = true;
    a.needsUpdate = true;
    return { kind: 'instances', prefix: order.prefix, perItem: 1 };
  }
  const a = g.attributes._birth_step;  // GLTFLoader lower-cases application-specific attribute names
  if (!a || !g.index) return null;
  const per = mesh.isLineSegments || mesh.isLine ? 2 : 3;
  const idx = g.index.array, n = Math.floor(idx.length / per);
  const steps = Float64Array.from({ length: a.count }, (_, i) => a.getX(i));
  const stepOf = t => {
    let s = 0;
    for (let k = 0; k < per; k++) s = Math.max(s, steps[idx[per * t + k]]);
    return s;
  };
  const order = countingOrder(n, stepOf, lastStep);
  const src = idx.slice();
  for (let j = 0; j < n; j++) {
    const t = order.items[j];
    for (let k = 0; k < per; k++) idx[per * j + k] = src[per * t + k];
  }
  g.index.needsUpdate = true;
  return { kind: 'range', prefix: order.prefix, perItem: per };
}
// items sorted by key (integers 0..last), stable; prefix[k] = how many have key <= k.
function countingOrder(n, key, last) {
  const counts = new Uint32Array(last + 2), keys = new Uint32Array(n);
  for (let i = 0; i < n; i++) {
    keys[i] = Math.min(last, Math.max(0, Math.round(key(i))));
    counts[keys[i] + 1]++;
  }
  for (let k = 1; k < counts.length; k++) counts[k] += counts[k - 1];
  const next = counts.slice(0, -1), items = new Uint32Array(n);
  for (let i = 0; i < n; i++) items[next[keys[i]]++] = i;
  return { items, prefix: counts.subarray(1) };
}
// The first and last birth steps of the plant's vertices and instances; [-1, -1] without any.
function birthStepRange(root) {
  let first = Infinity, last = -1;
  root.traverse(o => {
    if (!o.isMesh && !o.isLine) return;
    const a = o.isInstancedMesh ? o.geometry.attributes._BIRTH_STEP : o.geometry.attributes._birth_step;
    if (!a) return;
    for (let i = 0; i < a.count; i++) {
      first = Math.min(first, a.getX(i));
      last = Math.max(last, a.getX(i));
    }
  });
  return last < 0 ? [-1, -1] : [first, last];
}

class Viewer {
  constructor(element, index) {
    this.el = element;
    this.index = index;
    this.parts = { branches: [], leaves: [], flowers: [] };
    this.growth = [];  // { mesh, prefix, kind, perItem }
    this.step = 0;
    this.lastStep = -1;
    this.playing = false;
    this.build();
  }
  build() {
    const el = this.el, d = el.dataset;
    el.innerHTML = '';
    this.renderer = new WebGLRenderer({ antialias: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    el.appendChild(this.renderer.domElement);
    this.status = append(el, 'div', 'gb-status', 'Loading…');
    const bar = append(el, 'div', 'gb-bar');
    this.toggles = {};
    for (const p of [...PARTS, 'scene']) {
      const label = append(bar, 'label');
      const box = append(label, 'input');
      box.type = 'checkbox';
      box.checked = true;
      box.dataset.part = p;
      box.addEventListener('change', () => this.setVisible(p, box.checked));
      label.append(' ' + p[0].toUpperCase() + p.slice(1));
      this.toggles[p] = box;
    }
    this.play = append(bar, 'button', 'gb-play', '▶ Play');
    this.play.addEventListener('click', () => this.togglePlay());
    this.slider = append(bar, 'input', 'gb-slider');
    this.slider.type = 'range';
    this.slider.min = 0;
    this.slider.addEventListener('input', () => this.setStep(+this.slider.value));
    this.stepLabel = append(bar, 'span', 'gb-step', '');
    const reset = append(bar, 'button', 'gb-reset', 'Reset view');
    reset.addEventListener('click', () => this.frame());
    for (const c of [this.play, this.slider]) c.disabled = true;
    this.resize();
    window.addEventListener('resize', () => { this.resize(); this.requestRender(); });
    if (d.autoload === 'false') {
      const mb = d.plantBytes ? ` (${(+d.plantBytes / 1048576).toFixed(1)} MB)` : '';
      const b = append(el, 'button', 'gb-load', `Load the 3D view${mb}`);
      this.status.textContent = 'Not loaded yet.';
      b.addEventListener('click', () => { b.remove(); this.load(); });
      setBodyState(this.index, 'deferred');
    } else {
      this.load();
    }
  }
  resize() {
    const w = this.el.clientWidth || 800, h = Math.round(Math.min(0.62 * w, 0.75 * window.innerHeight || 600));
    this.renderer.setSize(w, h);
    if (this.camera) {
      this.camera.aspect = w / h;
      this.camera.updateProjectionMatrix();
    }
  }
  async load() {
    const d = this.el.dataset, t0 = performance.now();
    setBodyState(this.index, 'loading');
    try {
      await MeshoptDecoder.ready;
      const [plantBytes, sceneBytes] = await Promise.all([loadData(d.plant, d.plantKey),
        d.scene ? loadData(d.scene, d.sceneKey) : null]);
      const t1 = performance.now();
      const [plant, scene] = await Promise.all([parseGlb(plantBytes), sceneBytes ? parseGlb(sceneBytes) : null]);
      const t2 = performance.now();
      this.setup(plant, scene);
      const t3 = performance.now();
      this.renderNow();
      this.timings = { load_ms: t1 - t0, parse_ms: t2 - t1, prepare_ms: t3 - t2, first_frame_ms: performance.now() - t3 };
      this.status.textContent = '';
      this.status.style.display = 'none';
      setBodyState(this.index, 'loaded');
    } catch (e) {
      this.status.textContent = `The 3D view failed: ${e.message || e}`;
      this.status.classList.add('error');
      setBodyState(this.index, 'error');
      console.error('growbench viewer:', e);
    }
  }
  setup(plant, sceneGltf) {
    const scene = this.scene = new Scene();
    scene.background = new Color(0xdfe7ee);
    this.plantRoot = plant.scene;
    scene.add(plant.scene);
    plant.scene.updateMatrixWorld(true);
    let light = null, sceneCamera = null;
    if (sceneGltf) {
      this.sceneRoot = sceneGltf.scene;
      scene.add(sceneGltf.scene);
      sceneGltf.scene.traverse(o => {
        if (o.isDirectionalLight || o.isPointLight) light = o;
        if (o.isCamera) sceneCamera = o;
        if (o.isMesh) o.material.side = 2;  // DoubleSide: the ground slab is seen from anywhere
      });
    } else {
      this.toggles.scene.disabled = true;
      this.toggles.scene.checked = false;
    }
    if (!light) {  // growbench's default sun, towards (0.3, 1, 0.5)
      light = new DirectionalLight(0xfff5e0, 3);
      light.position.set(0.3, 1, 0.5);
      scene.add(light);
    }
    scene.add(new HemisphereLight(0xdde8ff, 0x5a5040, 1.2));
    scene.add(new AmbientLight(0xffffff, 0.15));
    // Parts and growth.
    const [firstStep, lastStep] = birthStepRange(plant.scene);
    this.lastStep = lastStep;
    // A plant whose every node appeared at one step (an L-system draws its final string at once) has
    // no growth to play.
    const grows = firstStep < lastStep;
    plant.scene.traverse(o => {
      if (!(o.isMesh || o.isLineSegments || o.isLine)) return;
      this.parts[partOf(o)].push(o);
      if (grows) {
        const gr = prepareGrowth(o, this.lastStep);
        if (gr) this.growth.push({ mesh: o, ...gr });
      }
    });
    for (const p of PARTS) if (!this.parts[p].length) {
      this.toggles[p].disabled = true;
      this.toggles[p].checked = false;
      this.toggles[p].parentElement.title = `this plant has no ${p}`;
    }
    if (this.growth.length) {
      this.slider.max = this.lastStep;
      this.slider.value = this.lastStep;
      this.slider.disabled = this.play.disabled = false;
      this.step = this.lastStep;
    } else {
      this.slider.style.visibility = this.play.style.visibility = 'hidden';
      this.stepLabel.textContent = lastStep < 0 ? 'no growth steps in this plant.glb'
        : `every node appeared at step ${lastStep}: no growth to play`;
    }
    // Camera: from the scene camera's side, framing the plant.
    // A plant with no geometry is framed by its scene, or failing that by a metre around the origin.
    let box = new Box3().setFromObject(plant.scene);
    if (box.isEmpty()) box = new Box3().setFromObject(scene);
    if (box.isEmpty()) box = new Box3(new Vector3(-0.5, 0, -0.5), new Vector3(0.5, 1, 0.5));
    this.plantBox = box;
    this.plantSphere = box.getBoundingSphere(new Sphere());
    const all = new Box3().setFromObject(scene);
    const fov = sceneCamera ? sceneCamera.fov : 45;
    this.camera = new PerspectiveCamera(fov, 1, Math.max(1e-3, all.getSize(new Vector3()).length() / 5000),
                                        all.getSize(new Vector3()).length() * 10);
    this.viewDir = new Vector3(0, 0.25, 1);
    if (sceneCamera) {
      sceneCamera.updateMatrixWorld(true);
      this.viewDir = sceneCamera.getWorldPosition(new Vector3()).sub(this.plantSphere.center);
    }
    this.viewDir.normalize();
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.requestRender());
    this.resize();
    this.frame();
    this.setStep(this.step);
  }
  // From the view direction, far enough that the bounding sphere fits, then nearer until the plant's box
  // spans most of the frame: a flat or thin plant would otherwise be small in the middle.
  frame() {
    const s = this.plantSphere, fov = this.camera.fov * Math.PI / 180;
    const fit = Math.min(fov, 2 * Math.atan(Math.tan(fov / 2) * this.camera.aspect));
    let dist = 1.15 * s.radius / Math.sin(fit / 2);
    const corners = [], b = this.plantBox, p = new Vector3();
    for (let i = 0; i < 8; i++) corners.push(new Vector3(i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y, i & 4 ? b.max.z : b.min.z));
    for (let k = 0; k < 4; k++) {
      this.camera.position.copy(s.center).addScaledVector(this.viewDir, dist);
      this.camera.lookAt(s.center);
      this.camera.updateMatrixWorld(true);
      let span = 0;
      for (const c of corners) {
        p.copy(c).project(this.camera);
        if (p.z > 1) { span = 2; break; }  // a corner behind the camera: keep the distance that fits the sphere
        span = Math.max(span, Math.abs(p.x), Math.abs(p.y));
      }
      if (!(span > 0) || span > 1.5) break;
      dist *= 0.5 + 0.5 * span / 0.85;  // halfway towards a span of 85% of the frame
    }
    this.camera.position.copy(s.center).addScaledVector(this.viewDir, dist);
    this.controls.target.copy(s.center);
    this.controls.update();
    this.requestRender();
  }
  setVisible(part, on) {
    if (part === 'scene') { if (this.sceneRoot) this.sceneRoot.visible = on; }
    else for (const m of this.parts[part]) m.visible = on;
    this.requestRender();
  }
  setStep(k) {
    this.step = Math.max(0, Math.min(this.lastStep, Math.round(k)));
    for (const g of this.growth) {
      const n = g.prefix[this.step];
      if (g.kind === 'instances') g.mesh.count = n;
      else g.mesh.geometry.setDrawRange(0, n * g.perItem);
    }
    if (this.growth.length) {
      this.slider.value = this.step;
      this.stepLabel.textContent = `step ${this.step} of ${this.lastStep}`;
    }
    this.requestRender();
  }
  togglePlay() {
    this.playing = !this.playing;
    this.play.textContent = this.playing ? '❚❚ Pause' : '▶ Play';
    if (!this.playing) return;
    if (this.step >= this.lastStep) this.setStep(0);
    const seconds = 8, start = performance.now(), from = this.step;
    const tick = now => {
      if (!this.playing) return;
      const k = from + (now - start) / 1000 / seconds * this.lastStep;
      this.setStep(k);
      if (k >= this.lastStep) return this.togglePlay();
      requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
  }
  requestRender() {
    if (this.pending || !this.scene) return;
    this.pending = true;
    requestAnimationFrame(() => { this.pending = false; this.renderNow(); });
  }
  renderNow() {
    this.renderer.render(this.scene, this.camera);
    const i = this.renderer.info.render;
    this.lastFrame = { triangles: i.triangles, lines: i.lines, calls: i.calls };
  }
  // Whether this frame is faithful, read from the geometry itself: every drawn triangle, line or organ
  // instance has a birth step <= the step shown, every hidden one a later step. Counts of each kind of wrong.
  frameCheck() {
    let drawnLater = 0, hiddenEarlier = 0, items = 0;
    for (const g of this.growth) {
      const geo = g.mesh.geometry;
      if (g.kind === 'instances') {
        const a = geo.attributes._BIRTH_STEP;
        for (let j = 0; j < a.count; j++, items++) {
          if (j < g.mesh.count && a.getX(j) > this.step) drawnLater++;
          if (j >= g.mesh.count && a.getX(j) <= this.step) hiddenEarlier++;
        }
        continue;
      }
      const a = geo.attributes._birth_step, idx = geo.index.array, per = g.perItem;
      const drawn = Math.min(geo.drawRange.count, idx.length) / per;
      for (let j = 0; j < idx.length / per; j++, items++) {
        let step = 0;
        for (let k = 0; k < per; k++) step = Math.max(step, a.getX(idx[per * j + k]));
        if (j < drawn && step > this.step) drawnLater++;
        if (j >= drawn && step <= this.step) hiddenEarlier++;
      }
    }
    return { step: this.step, items, drawnLater, hiddenEarlier };
  }
  // What is drawn: the renderer's counts of the last frame, and the plant's index and instance counts
  // at this step (visible parts only).
  stats() {
    let indices = 0, instances = 0;
    for (const p of PARTS) for (const m of this.parts[p]) {
      if (!m.visible) continue;
      const g = m.geometry, n = g.index ? g.index.count : g.attributes.position.count;
      const drawn = Math.min(n, g.drawRange.count);
      if (m.isInstancedMesh) { indices += drawn * m.count; instances += m.count; } else indices += drawn;
    }
    return { step: this.step, lastStep: this.lastStep, indices, instances, frame: this.lastFrame,
             camera: this.camera ? this.camera.position.toArray() : null,
             parts: Object.fromEntries(PARTS.map(p => [p, this.parts[p].length])), growthMeshes: this.growth.length,
             timings: this.timings };
  }
}

function append(parent, tag, cls, text) {
  const e = document.createElement(tag);
  if (cls) e.className = cls;
  if (text) e.textContent = text;
  parent.appendChild(e);
  return e;
}

const viewers = [];
function mountAll() {
  if (!document.getElementById('gb-viewer-css')) {
    const style = document.createElement('style');
    style.id = 'gb-viewer-css';
    style.textContent = CSS;
    document.head.appendChild(style);
  }
  document.querySelectorAll('.gb-viewer').forEach(el => {
    if (el.gbViewer) return;
    setBodyState(viewers.length, 'loading');
    el.gbViewer = new Viewer(el, viewers.length);
    viewers.push(el.gbViewer);
  });
}
self.GBViewer = { viewers, mountAll };
if (document.readyState === 'loading') document.addEventListener('DOMContentLoaded', mountAll);
else mountAll();
