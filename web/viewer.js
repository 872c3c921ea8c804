// The 3-D view of seam's HTML report (docs/report.md). Bundled with three.js by web/build.mjs into one minified
// script that src/report/report.cpp inlines into every report: the page never loads anything from the network.
//
// Input: the JSON in <script id="seam-view-data" type="application/json"> (written by htmlReport):
//   meshes  [{name, p: [x,y,z,...], n: [nx,ny,nz,...], i: [triangle indices]}]   one per shaded patch
//   seams   [{k, v: verdict 0..4 (gap kink crease G1 G2) or -1 (failed), c: [x,y,z,...] points along the seam,
//             a, b: patch names, w: [x,y,z] worst point or null, s: {t, g1, g2} samples for the spikes or null,
//             plot: true when the page has its plots (#seam-k),
//             l: the value label ("#k kink 0.618°") of the worst gaps and kinks, absent on the others,
//             lr: its rank in the seam table (0 = the worst)}]
//   outline [[x,y,z,...]]   other boundary curves
//   free    [[x,y,z,...]]   free (naked) edges: no other face continues them (drawn in NAKED_COLOUR)
//   tol     {g1, g2}        the angle (deg) and relative curvature tolerances: no spike below them
// Output: a canvas in #view3d; the 2-D drawing (#view2d) stays when WebGL is not available. window.seamView is a
// small hook for the browser test (tests/report_view_test.mjs).
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const VERDICT_COLOURS = ['#d62728', '#ff7f0e', '#9467bd', '#1f77b4', '#2ca02c', '#bcbd22'];
const FAILED_COLOUR = '#000000';
const OUTLINE_COLOUR = '#9a9a9a';
const NAKED_COLOUR = '#e377c2';   // src/report/report.cpp kNakedEdgeColour

function webglAvailable() {
  try {
    const c = document.createElement('canvas');
    return !!(window.WebGLRenderingContext && (c.getContext('webgl2') || c.getContext('webgl')));
  } catch (e) {
    return false;
  }
}

// Zebra stripes: the reflected view direction in world space against a set of parallel light bands (as CAD zebra
// analysis): stripes bend where the normal turns, jump at a kink (G0 only) and break their curvature at a G1 seam.
const zebraVertex = `
varying vec3 vNormalW; varying vec3 vPosW;
void main() {
  vNormalW = normalize(mat3(modelMatrix) * normal);
  vec4 w = modelMatrix * vec4(position, 1.0);
  vPosW = w.xyz;
  gl_Position = projectionMatrix * viewMatrix * w;
}`;
const zebraFragment = `
uniform float stripes; varying vec3 vNormalW; varying vec3 vPosW;
void main() {
  vec3 n = normalize(vNormalW);
  vec3 v = normalize(vPosW - cameraPosition);
  if (dot(n, v) > 0.0) n = -n;
  vec3 r = reflect(v, n);
  float s = step(0.5, fract(stripes * acos(clamp(r.z, -1.0, 1.0)) / 3.14159265));
  gl_FragColor = vec4(vec3(0.08 + 0.88 * s), 1.0);
}`;

function start() {
  const dataEl = document.getElementById('seam-view-data');
  const host = document.getElementById('view3d');
  if (!dataEl || !host) return;
  if (!webglAvailable()) {
    host.style.display = 'none';
    const note = document.getElementById('view3d-note');
    if (note) note.textContent = 'WebGL is not available in this browser: the 2-D drawing below is the view.';
    return;
  }
  const data = JSON.parse(dataEl.textContent);
  document.getElementById('view3d-ui').style.display = '';
  const view2d = document.getElementById('view2d');
  if (view2d) view2d.open = false;   // the 2-D drawing stays one click away
  const canvasHost = document.getElementById('view3d-canvas');
  const width = canvasHost.clientWidth || 720, height = canvasHost.clientHeight || 540;

  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
  renderer.setSize(width, height);
  renderer.setClearColor(0xffffff, 1);
  canvasHost.appendChild(renderer.domElement);

  const scene = new THREE.Scene();
  const box = new THREE.Box3();
  const grow = (arr) => {
    for (let i = 0; i + 2 < arr.length; i += 3) box.expandByPoint(new THREE.Vector3(arr[i], arr[i + 1], arr[i + 2]));
  };
  data.meshes.forEach((m) => grow(m.p));
  data.seams.forEach((s) => grow(s.c));
  data.outline.forEach((c) => grow(c));
  (data.free || []).forEach((c) => grow(c));
  if (box.isEmpty()) box.set(new THREE.Vector3(-1, -1, -1), new THREE.Vector3(1, 1, 1));
  const centre = box.getCenter(new THREE.Vector3());
  const diag = Math.max(box.getSize(new THREE.Vector3()).length(), 1e-12);

  // ---- shaded patches (two materials: shaded and zebra)
  const shaded = new THREE.MeshStandardMaterial({
    color: 0xc8ccd4, metalness: 0.1, roughness: 0.55, side: THREE.DoubleSide,
    polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
  });
  const zebra = new THREE.ShaderMaterial({
    uniforms: { stripes: { value: 12.0 } }, vertexShader: zebraVertex, fragmentShader: zebraFragment,
    side: THREE.DoubleSide, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
  });
  const meshes = [];
  const meshByName = new Map();
  for (const m of data.meshes) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(m.p, 3));
    g.setAttribute('normal', new THREE.Float32BufferAttribute(m.n, 3));
    g.setIndex(m.i);
    const mesh = new THREE.Mesh(g, shaded);
    mesh.name = m.name;
    scene.add(mesh);
    meshes.push(mesh);
    meshByName.set(m.name, m);
  }
  scene.add(new THREE.HemisphereLight(0xffffff, 0x667080, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 1.6);
  scene.add(sun);

  // ---- seams coloured by verdict, other boundaries thin grey, worst points
  const lineOf = (arr, colour) => {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(arr, 3));
    return new THREE.Line(g, new THREE.LineBasicMaterial({ color: colour }));
  };
  const outlineGroup = new THREE.Group();
  data.outline.forEach((c) => outlineGroup.add(lineOf(c, OUTLINE_COLOUR)));
  scene.add(outlineGroup);
  const nakedGroup = new THREE.Group();   // over the outline: a naked edge is never hidden as "other boundary"
  (data.free || []).forEach((c) => {
    const line = lineOf(c, NAKED_COLOUR);
    line.renderOrder = 1;
    nakedGroup.add(line);
  });
  scene.add(nakedGroup);
  const seamGroup = new THREE.Group();
  const worstPts = [], worstCols = [];
  for (const s of data.seams) {
    const colour = s.v >= 0 ? VERDICT_COLOURS[s.v] : FAILED_COLOUR;
    const line = lineOf(s.c, colour);
    line.userData.k = s.k;
    seamGroup.add(line);
    if (s.w && (s.v < 3 || s.v === 5)) {   // gaps, kinks, creases, undetermined and failed seams: their worst point
      worstPts.push(s.w[0], s.w[1], s.w[2]);
      const c = new THREE.Color(colour);
      worstCols.push(c.r, c.g, c.b);
    }
  }
  scene.add(seamGroup);
  if (worstPts.length) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(worstPts, 3));
    g.setAttribute('color', new THREE.Float32BufferAttribute(worstCols, 3));
    const pts = new THREE.Points(g, new THREE.PointsMaterial({ size: 7, sizeAttenuation: false, vertexColors: true,
                                                                depthTest: false }));
    pts.renderOrder = 2;
    scene.add(pts);
  }

  // ---- spikes along the seams (CATIA Connect Checker style): at each sample a segment along the surface normal
  // (perpendicular to the seam), its length proportional to the G1 angle or the relative G2 jump; the largest value
  // of the model gets 8 % of the model's diagonal.
  const normalNear = (names, p) => {
    let best = null, bestD = Infinity;
    for (const name of names) {
      const m = meshByName.get(name);
      if (!m) continue;
      for (let i = 0; i + 2 < m.p.length; i += 3) {
        const dx = m.p[i] - p.x, dy = m.p[i + 1] - p.y, dz = m.p[i + 2] - p.z;
        const d = dx * dx + dy * dy + dz * dz;
        if (d < bestD) { bestD = d; best = [m, i]; }
      }
    }
    if (!best) return null;
    const [m, i] = best;
    return new THREE.Vector3(m.n[i], m.n[i + 1], m.n[i + 2]).normalize();
  };
  const pointAt = (c, f) => {   // the polyline c at fraction f of its points (points are uniform in the parameter)
    const n = c.length / 3 - 1;
    const x = Math.min(Math.max(f, 0), 1) * n, i = Math.min(Math.floor(x), n - 1), a = x - i;
    const p = new THREE.Vector3(c[3 * i], c[3 * i + 1], c[3 * i + 2]);
    if (n < 1) return { p, t: new THREE.Vector3(1, 0, 0) };
    const q = new THREE.Vector3(c[3 * i + 3], c[3 * i + 4], c[3 * i + 5]);
    return { p: p.clone().lerp(q, a), t: q.clone().sub(p).normalize() };
  };
  const spikeGroups = {};
  const tol = data.tol || { g1: 0, g2: 0 };
  for (const measure of ['g1', 'g2']) {
    let maxV = 0, drawn = 0, minDrawn = Infinity;
    // Design creases (verdict 2) get no spikes: their angle is intended and would dwarf every defect's spikes.
    const spiked = data.seams.filter((s) => s.s && s.v !== 2 && s.c.length >= 6);
    // The noise floor: values below the tolerance are not drawn, so round-off (the teapot's 5e-13 deg) never gets
    // a full-length spike of its own.
    const shown = (v) => Number.isFinite(v) && v >= tol[measure] && v > 0;
    spiked.forEach((s) => s.s[measure].forEach((v) => { if (shown(v)) maxV = Math.max(maxV, v); }));
    const pos = [], col = [];
    if (maxV > 0) {
      for (const s of spiked) {
        const ts = s.s.t, vs = s.s[measure];
        const t0 = ts[0], t1 = ts[ts.length - 1] > t0 ? ts[ts.length - 1] : t0 + 1;
        const colour = new THREE.Color(s.v >= 0 ? VERDICT_COLOURS[s.v] : FAILED_COLOUR);
        let tip = null;
        for (let j = 0; j < ts.length; ++j) {
          if (!shown(vs[j])) { tip = null; continue; }
          ++drawn;
          minDrawn = Math.min(minDrawn, vs[j]);
          const { p, t } = pointAt(s.c, (ts[j] - t0) / (t1 - t0));
          let dir = normalNear([s.a, s.b], p);
          if (!dir) dir = t.clone().cross(p.clone().sub(centre)).normalize();
          dir.sub(t.clone().multiplyScalar(dir.dot(t))).normalize();   // perpendicular to the seam
          const q = p.clone().addScaledVector(dir, 0.08 * diag * vs[j] / maxV);
          pos.push(p.x, p.y, p.z, q.x, q.y, q.z);
          col.push(colour.r, colour.g, colour.b, colour.r, colour.g, colour.b);
          if (tip) { pos.push(tip.x, tip.y, tip.z, q.x, q.y, q.z); col.push(colour.r, colour.g, colour.b, colour.r, colour.g, colour.b); }
          tip = q;
        }
      }
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    g.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
    const seg = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ vertexColors: true }));
    seg.visible = false;
    scene.add(seg);
    spikeGroups[measure] = { seg, maxV, drawn, minDrawn };
  }

  // ---- camera and controls
  const camera = new THREE.PerspectiveCamera(35, width / height, diag * 1e-3, diag * 100);
  const home = () => {
    camera.position.copy(centre).add(new THREE.Vector3(1, -1.2, 0.9).normalize().multiplyScalar(1.35 * diag));
    camera.up.set(0, 0, 1);
    controls.target.copy(centre);
    controls.update();
  };
  const controls = new OrbitControls(camera, renderer.domElement);
  controls.enableDamping = false;
  home();
  // ---- value labels (Rhino's edge analysis style): HTML boxes over the canvas at the worst points of the worst
  // gaps and kinks, moved with the view; hidden behind the camera or outside the canvas.
  // In the table's order (s.lr: the label's rank), so that where labels would overlap the worse seam's stays put and
  // the next one moves down below it.
  const labelled = data.seams.filter((s) => s.l && s.w).sort((a, b) => (a.lr ?? 0) - (b.lr ?? 0));
  const labelDivs = labelled.map((s) => {
    const d = document.createElement('div');
    d.className = 'v3label';
    d.textContent = s.l;
    d.setAttribute('data-seam', String(s.k));
    d.style.borderColor = s.v >= 0 ? VERDICT_COLOURS[s.v] : FAILED_COLOUR;
    canvasHost.appendChild(d);
    return d;
  });
  let labelsOn = true;
  const placeLabels = () => {
    const placed = [];   // boxes of the labels shown so far: [left, top, right, bottom]
    labelled.forEach((s, i) => {
      const d = labelDivs[i];
      const v = new THREE.Vector3(s.w[0], s.w[1], s.w[2]).project(camera);
      const x = (v.x + 1) / 2 * width;
      let y = (1 - v.y) / 2 * height;
      const inside = v.z < 1 && x >= 0 && x <= width && y >= 0 && y <= height;
      d.style.display = labelsOn && inside ? '' : 'none';
      if (d.style.display !== 'none') {
        const w = d.offsetWidth, h = d.offsetHeight;
        const hit = () => placed.find((b) => x + 6 < b[2] && x + 6 + w > b[0] && y - h / 2 < b[3] && y + h / 2 > b[1]);
        for (let tries = 0, b = hit(); b && tries < 8; ++tries, b = hit()) y = b[3] + h / 2 + 1;
        placed.push([x + 6, y - h / 2, x + 6 + w, y + h / 2]);
      }
      d.style.left = `${x.toFixed(1)}px`;
      d.style.top = `${y.toFixed(1)}px`;
    });
  };
  const render = () => {
    sun.position.copy(camera.position).add(new THREE.Vector3(0, 0, diag));
    renderer.render(scene, camera);
    placeLabels();
  };
  controls.addEventListener('change', render);

  // ---- the controls of the view
  const byId = (id) => document.getElementById(id);
  byId('view3d-zebra').addEventListener('change', (e) => {
    meshes.forEach((m) => { m.material = e.target.checked ? zebra : shaded; });
    render();
  });
  byId('view3d-spikes').addEventListener('change', (e) => {
    const v = e.target.value;
    spikeGroups.g1.seg.visible = v === 'g1';
    spikeGroups.g2.seg.visible = v === 'g2';
    const sc = byId('view3d-spike-scale');
    const floor = (m, unit) => `values below the tolerance (${tol[m]}${unit}) not drawn`;
    const scale = (m, unit) => spikeGroups[m].drawn > 0
      ? `longest spike: ${spikeGroups[m].maxV.toPrecision(3)}${unit}; ${floor(m, unit)}`
      : `no value at or above the tolerance (${tol[m]}${unit}): no spikes`;
    if (sc) sc.textContent = v === 'none' ? '' : v === 'g1' ? scale('g1', '\u00b0') : scale('g2', ' relative');
    render();
  });
  byId('view3d-outline').addEventListener('change', (e) => { outlineGroup.visible = e.target.checked; render(); });
  byId('view3d-labels').addEventListener('change', (e) => { labelsOn = e.target.checked; render(); });
  byId('view3d-home').addEventListener('click', () => { home(); render(); });

  // ---- clicking a seam: the nearest seam within 8 px on screen opens its plots in the panel
  const project = (x, y, z) => {
    const v = new THREE.Vector3(x, y, z).project(camera);
    const r = renderer.domElement.getBoundingClientRect();
    return { x: r.left + (v.x + 1) / 2 * r.width, y: r.top + (1 - v.y) / 2 * r.height, z: v.z };
  };
  const distToSeam = (s, px, py) => {
    let best = Infinity;
    let prev = null;
    for (let i = 0; i + 2 < s.c.length; i += 3) {
      const q = project(s.c[i], s.c[i + 1], s.c[i + 2]);
      if (prev) {
        const dx = q.x - prev.x, dy = q.y - prev.y, l2 = dx * dx + dy * dy;
        const a = l2 > 0 ? Math.min(Math.max(((px - prev.x) * dx + (py - prev.y) * dy) / l2, 0), 1) : 0;
        best = Math.min(best, Math.hypot(prev.x + a * dx - px, prev.y + a * dy - py));
      } else {
        best = Math.hypot(q.x - px, q.y - py);
      }
      prev = q;
    }
    return best;
  };
  const pickAt = (px, py) => {
    let best = null, bestD = 8;
    for (const s of data.seams) {
      const d = distToSeam(s, px, py);
      if (d < bestD) { bestD = d; best = s; }
    }
    return best;
  };
  const panel = byId('view3d-panel');
  let selected = null;   // the clicked seam drawn again in black over everything
  const showSeam = (s) => {
    if (selected) { scene.remove(selected); selected.geometry.dispose(); }
    selected = lineOf(s.c, '#000000');
    selected.material.depthTest = false;
    selected.renderOrder = 3;
    scene.add(selected);
    panel.setAttribute('data-seam', String(s.k));
    const plots = s.plot ? byId('seam-' + s.k) : null;
    panel.innerHTML = '';
    if (plots) {
      panel.appendChild(plots.cloneNode(true)).removeAttribute('id');
    } else {
      panel.textContent = `Seam #${s.k} (${s.a} / ${s.b}): no plots on this page (see --max-plots).`;
    }
    render();
  };
  let down = null;
  renderer.domElement.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
  renderer.domElement.addEventListener('pointerup', (e) => {
    if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;   // a drag rotates
    const s = pickAt(e.clientX, e.clientY);
    if (s) showSeam(s);
  });

  render();
  window.seamView = {
    ready: true,
    seams: data.seams.length,
    meshes: data.meshes.length,
    nakedEdges: (data.free || []).length,
    // Spikes drawn for a measure ('g1', 'g2'), the smallest value among them, and the tolerance (the noise floor).
    spikes(m) { return { drawn: spikeGroups[m].drawn, minDrawn: spikeGroups[m].minDrawn, tol: tol[m] }; },
    // Screen point (client coordinates) of the middle of seam k, and whether no other seam is within 12 px there.
    seamScreenPoint(k) {
      const s = data.seams.find((x) => x.k === k);
      const n = s.c.length / 3, i = Math.floor((n - 1) / 2);
      const q = project(s.c[3 * i], s.c[3 * i + 1], s.c[3 * i + 2]);
      const clear = data.seams.every((o) => o === s || distToSeam(o, q.x, q.y) > 12);
      return { x: q.x, y: q.y, clear, plot: !!s.plot };
    },
    seamIndices() { return data.seams.map((s) => s.k); },
    // The value labels: seam index, text, shown or not, and the label's anchor in client coordinates.
    labels() {
      const r = renderer.domElement.getBoundingClientRect();
      return labelled.map((s, i) => ({
        k: s.k, text: labelDivs[i].textContent, shown: labelDivs[i].style.display !== 'none',
        x: r.left + parseFloat(labelDivs[i].style.left), y: r.top + parseFloat(labelDivs[i].style.top),
      }));
    },
  };
}

if (document.readyState === 'loading') document.addEventListener('DOMContentLoaded', start);
else start();
