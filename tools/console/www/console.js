// console.js: the sonocomp instructor console (docs/console.md). Talks to sc-gateway over one
// WebSocket: binary state records ('S' + record, docs/state-stream.md) and B-scan frames ('B'),
// JSON replies; sends the JSON commands of tools/gateway/gw_msg.h.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { createScanner, decodeBscan } from './scanner.js';

const HEALTH = ['init', 'running', 'degraded', 'fault'];
const LABEL = { 4: 'vein', 5: 'artery', 7: 'thrombus' };
const COLOR = { 0: 0xd9a58b, 4: 0x0000ff, 5: 0xff0000, 7: 0x553300 };
const $ = (id) => document.getElementById(id);

// ---- state shared with the tests (window.sc) ------------------------------------------------
const sc = {
  frame: null, surf: null, catalogue: [], replies: [], errors: [], bscanFrames: 0, sessions: [], replay: null, replays: [],
  records: 0, gaps: 0, lastSeq: -1, frozen: false, assessment: null, material: null,
};
window.sc = sc;

// ---- 3D scene ---------------------------------------------------------------------------------
const canvas = $('scene');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x1a1a1a);
const camera = new THREE.PerspectiveCamera(40, 1, 1, 5000);
const ortho = new THREE.OrthographicCamera(-30, 30, 30, -30, -2000, 2000);
let active = camera;
const controls = new OrbitControls(camera, canvas);
scene.add(new THREE.AmbientLight(0xffffff, 0.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.2);
sun.position.set(100, 300, 200);
scene.add(sun);
// the volume frame (x, y lateral, z depth down) -> three.js (x, -z, y): z points down on screen
const root = new THREE.Group();
root.rotation.x = Math.PI / 2;
scene.add(root);

const probe = new THREE.Group();
root.add(probe);
const probeBody = new THREE.Mesh(new THREE.BoxGeometry(40, 10, 60),
  new THREE.MeshStandardMaterial({ color: 0xcccccc, transparent: true, opacity: 0.5 }));
probeBody.position.z = -30; // the handle above the face; the beam is +z
probe.add(probeBody);
const imageGroup = new THREE.Group(); // image -> probe calibration
probe.add(imageGroup);
const bscanCanvas = $('bscan');
// the scanner display (scanner.js): the panel with its overlay; the plane shows its image
// (scan-converted grey and colour, transparent outside the image), skin row at the face
const scanner = createScanner(bscanCanvas, $('spectrum'));
const bscanTex = new THREE.CanvasTexture(scanner.image);
bscanTex.magFilter = THREE.LinearFilter;
bscanTex.flipY = false; // canvas row 0 (the skin) at the plane's -y, which is image z = 0 side
const plane = new THREE.Mesh(new THREE.PlaneGeometry(1, 1),
  new THREE.MeshBasicMaterial({ map: bscanTex, side: THREE.DoubleSide, transparent: true, opacity: 0.85 }));
plane.rotation.x = Math.PI / 2; // plane's y -> image z (depth)
imageGroup.add(plane);

let surfaces = []; // {label, kind, first, count, triCount, mesh}
let positions = null; // Float32Array(nv*3), global
let triangles = null; // Uint32Array(nt*3), global
let trisSeen = null;  // Uint8Array(nt)
let caseCrc = -1;
let geomDirty = false;
let fitted = false;
let measuring = null; // the surface of the measurement view, when on

function resetSurfaces(info) {
  for (const s of surfaces) { root.remove(s.mesh); s.mesh.geometry.dispose(); }
  surfaces = [];
  positions = new Float32Array(info.nv * 3);
  triangles = new Uint32Array(info.nt * 3);
  trisSeen = new Uint8Array(info.nt);
  fitted = false;
  for (const s of info.surfaces) {
    const g = new THREE.BufferGeometry();
    const view = positions.subarray(s.first * 3, (s.first + s.count) * 3);
    g.setAttribute('position', new THREE.BufferAttribute(view, 3));
    const skin = s.kind === 0;
    const mat = skin
      ? new THREE.MeshStandardMaterial({ color: COLOR[0], transparent: true, opacity: 0.35, side: THREE.DoubleSide, depthWrite: false })
      : new THREE.MeshBasicMaterial({ color: COLOR[s.label] ?? 0x888888, side: THREE.DoubleSide });
    const mesh = new THREE.Mesh(g, mat);
    mesh.name = skin ? 'skin' : (LABEL[s.label] ?? 'label' + s.label);
    mesh.visible = false;
    mesh.renderOrder = skin ? 2 : 1;
    root.add(mesh);
    surfaces.push({ ...s, mesh, indexDone: false });
  }
}

function rebuildIndex(s) {
  const idx = new Uint32Array(s.triCount * 3);
  for (let t = 0; t < s.triCount * 3; t++) idx[t] = triangles[s.firstTri * 3 + t] - s.first;
  s.mesh.geometry.setIndex(new THREE.BufferAttribute(idx, 1));
  s.mesh.visible = measuring ? s === measuring : (s.kind !== 0 || $('show-skin').checked);
  s.indexDone = true;
}

function fitView() {
  const box = new THREE.Box3();
  for (const s of surfaces) if (s.mesh.visible) box.expandByObject(s.mesh);
  if (box.isEmpty()) return;
  const c = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3()).length();
  controls.target.copy(c);
  camera.position.set(c.x + size * 0.6, c.y + size * 0.5, c.z + size * 0.9);
  controls.update();
  fitted = true;
}

function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== w || canvas.height !== h) {
    renderer.setSize(w, h, false);
    camera.aspect = w / h; camera.updateProjectionMatrix();
    const a = w / h; ortho.left = -30 * a; ortho.right = 30 * a; ortho.updateProjectionMatrix();
    needsRender = true;
  }
}

// render on demand, at most 30 times a second: a tablet's battery and a loaded kiosk's CPU
let needsRender = true, lastRender = 0;
const redraw = () => { needsRender = true; };
controls.addEventListener('change', redraw);

function animate(t) {
  requestAnimationFrame(animate);
  if (t - lastRender < 33) return;
  resize();
  if (geomDirty && !sc.frozen) {
    for (const s of surfaces) {
      s.mesh.geometry.attributes.position.needsUpdate = true;
      s.mesh.geometry.computeVertexNormals();
      s.mesh.geometry.computeBoundingSphere();
    }
    geomDirty = false;
    needsRender = true;
    if (!fitted && surfaces.every((s) => s.indexDone)) fitView();
  }
  if (active === camera) controls.update();
  if (!needsRender) return;
  needsRender = false;
  lastRender = t;
  renderer.render(scene, active);
}
requestAnimationFrame(animate);

$('view-reset').onclick = () => { active = camera; fitView(); redraw(); };
$('show-skin').onchange = () => { for (const s of surfaces) if (s.kind === 0) s.mesh.visible = $('show-skin').checked && s.indexDone; };
$('freeze').onchange = () => { sc.frozen = $('freeze').checked; };

// A fixed view for measurements (tests, docs): orthographic, looking along the vessel's long
// axis at rest through a thin slab at its middle, skin and probe hidden, only the vessel
// labelled `label` shown.
window.scMeasureView = (label = 4, slabMm = 8) => {
  const s = surfaces.find((x) => x.kind === 1 && x.label === label);
  if (!s) return false;
  measuring = s;
  for (const x of surfaces) x.mesh.visible = x === s;
  probe.visible = false;
  s.mesh.geometry.computeBoundingBox();
  const bb = s.mesh.geometry.boundingBox; // volume frame
  const size = bb.getSize(new THREE.Vector3()), c = bb.getCenter(new THREE.Vector3());
  const along = size.x >= size.y ? 'x' : 'y';
  const cw = root.localToWorld(c.clone());
  const dir = along === 'x' ? new THREE.Vector3(1, 0, 0) : new THREE.Vector3(0, 0, 1); // in world
  ortho.position.copy(cw).addScaledVector(dir, 500);
  ortho.up.set(0, 1, 0);
  ortho.lookAt(cw);
  const half = Math.max(size.z, along === 'x' ? size.y : size.x) * 0.8;
  const a = canvas.clientWidth / canvas.clientHeight;
  ortho.top = half; ortho.bottom = -half; ortho.left = -half * a; ortho.right = half * a;
  // a slab 8 mm thick across the vessel where the probe presses (the middle of the case's
  // mesh top, where the phantoms put their vessels): the section the probe flattens
  ortho.near = 500 - slabMm / 2; ortho.far = 500 + slabMm / 2;
  ortho.updateProjectionMatrix();
  active = ortho;
  needsRender = true;
  return true;
};
window.scNormalView = () => {
  measuring = null;
  for (const s of surfaces) s.mesh.visible = s.indexDone && (s.kind !== 0 || $('show-skin').checked);
  probe.visible = true; active = camera; needsRender = true;
};

// ---- B-scan -----------------------------------------------------------------------------------
function onBscan(dv, u8) {
  sc.bscanFrames++;
  if (sc.frozen) return;
  const f = decodeBscan(dv, u8);
  if (!f) { sc.bscanBad = (sc.bscanBad ?? 0) + 1; return; }
  scanner.draw(f);
  sc.scanner = scanner.state;
  bscanTex.needsUpdate = true;
  needsRender = true;
  const e = scanner.planeExtent();
  plane.scale.set(e.width, e.height, 1);
  plane.position.set(0, 0, e.centreZ);
}
window.scScannerImage = () => scanner.image;
// a vessel's section in the image plane, in panel pixels (tests): the bounding box of where the
// vessel's surface triangles (the live mesh) cross the image plane (image frame y = 0)
window.scSectionPx = (label) => {
  const s = surfaces.find((x) => x.kind === 1 && x.label === label);
  if (!s || !s.indexDone || !positions) return null;
  root.updateMatrixWorld(true);
  const toImage = new THREE.Matrix4().copy(plane.parent.matrixWorld).invert().multiply(root.matrixWorld);
  const idx = s.mesh.geometry.index.array, pos = s.mesh.geometry.attributes.position.array;
  const v = [0, 1, 2].map(() => new THREE.Vector3());
  let x0 = Infinity, x1 = -Infinity, z0 = Infinity, z1 = -Infinity, n = 0;
  for (let t = 0; t < idx.length; t += 3) {
    for (let j = 0; j < 3; j++) v[j].fromArray(pos, idx[t + j] * 3).applyMatrix4(toImage);
    for (let j = 0; j < 3; j++) {
      const a = v[j], b = v[(j + 1) % 3];
      if ((a.y < 0) === (b.y < 0)) continue;
      const u = a.y / (a.y - b.y), x = a.x + u * (b.x - a.x), z = a.z + u * (b.z - a.z);
      x0 = Math.min(x0, x); x1 = Math.max(x1, x); z0 = Math.min(z0, z); z1 = Math.max(z1, z); n++;
    }
  }
  if (n === 0) return null;
  const p0 = scanner.toPanel(x0, z0), p1 = scanner.toPanel(x1, z1);
  return p0 && p1 ? { x0: p0[0], y0: p0[1], x1: p1[0], y1: p1[1], mm: { x0, x1, z0, z1 } } : null;
};

// ---- state records ----------------------------------------------------------------------------
function text(u8, off, n) {
  let s = '';
  for (let i = 0; i < n && u8[off + i]; i++) s += String.fromCharCode(u8[off + i]);
  return s;
}

function onFrame(dv, p) {
  const f = {
    health: HEALTH[dv.getUint8(p + 8)] ?? '?', caseLoaded: dv.getUint8(p + 9), caseId: dv.getUint8(p + 10),
    method: dv.getUint8(p + 11) === 1 ? 'fem' : 'msds', tracked: dv.getUint8(p + 12), contact: dv.getUint8(p + 13),
    switching: dv.getUint8(p + 14), faults: dv.getUint32(p + 16, true), geometry: dv.getUint32(p + 20, true),
    frames: Number(dv.getBigUint64(p + 24, true)), misses: Number(dv.getBigUint64(p + 32, true)),
    worstMs: Number(dv.getBigUint64(p + 40, true)) / 1e6, p99Ms: Number(dv.getBigUint64(p + 48, true)) / 1e6,
    vein: dv.getFloat32(p + 56, true), artery: dv.getFloat32(p + 60, true),
    pos: [0, 1, 2].map((i) => dv.getFloat32(p + 64 + 4 * i, true)),
    q: [0, 1, 2, 3].map((i) => dv.getFloat32(p + 76 + 4 * i, true)),
    gainDb: dv.getFloat32(p + 92, true), dynRangeDb: dv.getFloat32(p + 96, true), depthMm: dv.getFloat32(p + 100, true),
    tgcDb: [...Array(8).keys()].map((i) => dv.getFloat32(p + 104 + 4 * i, true)),
    commandsApplied: Number(dv.getBigUint64(p + 136, true)), commandsRefused: Number(dv.getBigUint64(p + 144, true)),
    authRefused: Number(dv.getBigUint64(p + 152, true)), caseLoads: Number(dv.getBigUint64(p + 160, true)),
    caseLoadFailures: Number(dv.getBigUint64(p + 168, true)), lastCaseError: dv.getInt32(p + 176, true),
    caseCrc: dv.getUint32(p + 180, true), streamDropped: dv.getUint32(p + 192, true),
  };
  sc.frame = f;
  if (sc.replay && sc.replay.state === 'running') {
    sc.replay.frame = f.frames;
    $('replay-status').textContent = `replaying ${sc.replay.name} (frame ${f.frames}/${sc.replay.frames})`;
  }
  if (sc.frozen) return;
  probe.position.set(f.pos[0], f.pos[1], f.pos[2]);
  probe.quaternion.set(f.q[1], f.q[2], f.q[3], f.q[0]);
  needsRender = true;
  renderStatus(f);
}

function renderStatus(f) {
  $('health').textContent = f.health;
  const rows = [
    ['case', f.caseLoaded ? `#${f.caseId}${f.switching ? ' (switching)' : ''}` : 'none'],
    ['method', f.method], ['probe', `${f.tracked ? 'tracked' : 'lifted'}${f.contact ? ', in contact' : ''}`],
    ['vein area', f.vein >= 0 ? f.vein.toFixed(3) : '-'], ['artery area', f.artery >= 0 ? f.artery.toFixed(3) : '-'],
    ['gain', `${f.gainDb.toFixed(1)} dB`], ['dynamic range', `${f.dynRangeDb.toFixed(0)} dB`],
    ['depth', `${f.depthMm.toFixed(0)} mm`], ['frames', f.frames], ['deadline misses', f.misses],
    ['worst frame', `${f.worstMs.toFixed(2)} ms`], ['faults', '0x' + f.faults.toString(16)],
    ['commands', `${f.commandsApplied} applied, ${f.commandsRefused} refused, ${f.authRefused} unauthenticated`],
    ['case switches', `${f.caseLoads} done, ${f.caseLoadFailures} refused`],
    ['stream', `${sc.records} records, ${sc.gaps} gaps, ${f.streamDropped} dropped at the engine`],
  ];
  const dl = $('status');
  dl.replaceChildren(...rows.flatMap(([k, v]) => {
    const dt = document.createElement('dt'), dd = document.createElement('dd');
    dt.textContent = k; dd.textContent = String(v); dd.dataset.testid = 'st-' + k.replace(/ /g, '-');
    return [dt, dd];
  }));
  // the switch shows the engine's method, except just after the user changed it (until applied)
  if (performance.now() > methodPendingUntil || f.method === pendingMethod) {
    for (const r of document.querySelectorAll('input[name=method]')) r.checked = r.value === f.method;
  }
  for (const li of $('catalogue').children) li.classList.toggle('running', f.caseLoaded && +li.dataset.index === f.caseId);
}

function onSurfInfo(dv, p, u8) {
  const info = { crc: dv.getUint32(p, true), count: dv.getUint32(p + 4, true), nv: dv.getUint32(p + 8, true), nt: dv.getUint32(p + 12, true), surfaces: [] };
  let firstTri = 0;
  for (let i = 0; i < info.count && i < 8; i++) {
    const o = p + 16 + 16 * i;
    const s = { label: dv.getUint8(o), kind: dv.getUint8(o + 1), first: dv.getUint32(o + 4, true), count: dv.getUint32(o + 8, true), triCount: dv.getUint32(o + 12, true), firstTri };
    firstTri += s.triCount;
    info.surfaces.push(s);
  }
  info.name = text(u8, p + 144, 64);
  const r = [...Array(9).keys()].map((i) => dv.getFloat32(p + 208 + 4 * i, true));
  const t = [0, 1, 2].map((i) => dv.getFloat32(p + 244 + 4 * i, true));
  sc.surf = info;
  $('casename').textContent = info.name;
  if (info.crc !== caseCrc) {
    caseCrc = info.crc;
    resetSurfaces(info);
    const m = new THREE.Matrix4().set(r[0], r[1], r[2], t[0], r[3], r[4], r[5], t[1], r[6], r[7], r[8], t[2], 0, 0, 0, 1);
    imageGroup.matrixAutoUpdate = false;
    imageGroup.matrix.copy(m);
  }
}

function onVerts(dv, p) {
  if (dv.getUint32(p, true) !== caseCrc || !positions || sc.frozen) return;
  const first = dv.getUint32(p + 4, true), n = dv.getUint16(p + 8, true);
  if ((first + n) * 3 > positions.length) return;
  for (let i = 0; i < n * 3; i++) positions[first * 3 + i] = dv.getFloat32(p + 12 + 4 * i, true);
  geomDirty = true;
}

function onTris(dv, p) {
  if (dv.getUint32(p, true) !== caseCrc || !triangles) return;
  const first = dv.getUint32(p + 4, true), n = dv.getUint16(p + 8, true);
  if (first + n > trisSeen.length) return;
  for (let i = 0; i < n * 3; i++) triangles[first * 3 + i] = dv.getUint32(p + 12 + 4 * i, true);
  trisSeen.fill(1, first, first + n);
  for (const s of surfaces) {
    if (s.indexDone) continue;
    let all = true;
    for (let t = s.firstTri; t < s.firstTri + s.triCount && all; t++) all = trisSeen[t] === 1;
    if (all) { rebuildIndex(s); geomDirty = true; }
  }
}

// ASSESSMENT: the engine's exam record (docs/assessment.md, 104 bytes little-endian)
const CRITERIA = ['vein imaged', 'compressed', 'artery spared', 'force safe', 'call correct',
                  'no arterial puncture'];
const CALLS = ['none', 'normal', 'DVT'];
function onAssessment(dv, p) {
  if (dv.byteLength < p + 104 || dv.getUint32(p, true) !== 1) return;
  const ves = ['vein', 'artery', 'thrombus'].map((name, v) => {
    const q = p + 20 + 20 * v;
    return { name, min: dv.getFloat32(q, true), force: dv.getFloat32(q + 4, true),
             inView: dv.getUint32(q + 8, true), coapted: dv.getUint8(q + 16) === 1 };
  });
  const a = {
    frames: dv.getUint32(p + 4, true), vessels: ves, peakForce: dv.getFloat32(p + 80, true),
    arteryOver: dv.getUint8(p + 88) === 1, call: CALLS[dv.getUint8(p + 89)] ?? '?',
    finding: CALLS[dv.getUint8(p + 90)] ?? '?', met: dv.getUint8(p + 91),
    points: [0, 1, 2, 3, 4].map((i) => dv.getUint8(p + 92 + i)),
    score: dv.getUint8(p + 97), scoreMax: dv.getUint8(p + 98),
    // revision 1 (byte 102): the needle's punctures and criterion 5 in bytes 99..101
    revision: dv.getUint8(p + 102), arteryPunctures: dv.getUint8(p + 99),
    veinPunctures: dv.getUint8(p + 100),
  };
  if (a.revision >= 1) a.points.push(dv.getUint8(p + 101));
  sc.assessment = a;
  $('assessment').hidden = false;
  const lines = [`score ${a.score}/${a.scoreMax}`];
  a.points.forEach((pts, i) => lines.push(`${(a.met >> i) & 1 ? '\u2713' : '\u2717'} ${CRITERIA[i]} (${pts})`));
  if (a.revision >= 1 && a.arteryPunctures + a.veinPunctures > 0)
    lines.push(`needle: ${a.veinPunctures} vein, ${a.arteryPunctures} arterial puncture(s)`);
  for (const v of ves) {
    if (v.inView > 0) lines.push(`${v.name}: min ratio ${v.min.toFixed(3)}${v.coapted ? ' (coapted)' : ''}` +
                                 (v.force >= 0 ? ` at ${v.force.toFixed(1)} N` : ''));
  }
  if (a.peakForce >= 0) lines.push(`peak force ${a.peakForce.toFixed(1)} N`);
  lines.push(`call ${a.call}; case finding ${a.call === 'none' ? 'hidden until the call' : a.finding}`);
  $('assessment-body').textContent = lines.join('\n');
}

function onRecord(buf) {
  const dv = new DataView(buf, 1), u8 = new Uint8Array(buf, 1);
  if (dv.byteLength < 16 || dv.getUint32(0, true) !== 0x54534353 || dv.getUint8(4) !== 1) return;
  const type = dv.getUint8(5), seq = dv.getUint32(8, true);
  if (sc.lastSeq >= 0 && seq !== ((sc.lastSeq + 1) >>> 0)) sc.gaps++;
  sc.lastSeq = seq; sc.records++;
  const p = 16;
  if (type === 1) onFrame(dv, p);
  else if (type === 2) onSurfInfo(dv, p, u8);
  else if (type === 3) onVerts(dv, p);
  else if (type === 4) onTris(dv, p);
  else if (type === 6) onAssessment(dv, p);
  else if (type === 7) onMaterial(dv, p);
  // CATALOGUE records reach the page as the gateway's JSON catalogue (with the case texts)
}

// ---- connection and commands ----------------------------------------------------------------
let ws = null;
function log(s) { const l = $('log'); l.textContent = (s + '\n' + l.textContent).slice(0, 4000); }
function send(obj) {
  const s = typeof obj === 'string' ? obj : JSON.stringify(obj);
  if (ws && ws.readyState === 1) ws.send(s);
}
window.scSend = send;

function onJson(m) {
  sc.replies.push(m);
  if (m.type === 'error') { sc.errors.push(m); log(`refused ${m.op}: ${m.reason}`); }
  else if (m.type === 'ack') log(`sent ${m.op}`);
  if (m.type === 'hello') $('lock').textContent = m.locked ? 'locked (viewing only)' : 'open';
  if (m.type === 'ack' && m.op === 'auth') $('lock').textContent = 'unlocked';
  if (m.type === 'catalogue') renderCatalogue(m.entries);
  if (m.type === 'hello' && m.sessions) { $('sessions-panel').hidden = false; send({ op: 'sessions' }); }
  if (m.type === 'sessions') renderSessions(m);
  if (m.type === 'replay') onReplay(m);
}

// ---- recorded sessions (sc-gateway --sessions DIR) ------------------------------------------
function renderSessions(m) {
  sc.sessions = m.entries;
  $('sessions').tBodies[0].replaceChildren(...m.entries.map((e) => {
    const tr = document.createElement('tr');
    tr.dataset.file = e.file;
    const cell = (t) => { const td = document.createElement('td'); td.textContent = t; return td; };
    const b = document.createElement('button');
    b.textContent = 'replay'; b.dataset.testid = 'replay-' + e.file; b.title = e.file;
    b.onclick = () => send({ op: 'replay', name: e.file });
    const first = document.createElement('td'); first.append(b);
    if (e.error) {
      b.disabled = true;
      const bad = cell(`${e.file}: refused (${e.error})`); bad.colSpan = 5; bad.className = 'desc';
      tr.append(first, bad);
    } else {
      tr.append(first, cell(e.case), cell(e.method), cell(e.date), cell(`${e.frames} (${e.seconds.toFixed(1)} s)`),
        cell(`${e.score}/${e.score_max}`));
    }
    return tr;
  }));
}

function onReplay(m) {
  // frame: the replay's newest frame seen (kept when it ends)
  sc.replay = { ...m, frame: m.state === 'running' ? 0 : (sc.replay?.frame ?? 0) };
  sc.replays.push(m);
  sc.lastSeq = -1; // another engine's sequence numbers follow (the gateway resets its own count too)
  if (m.state === 'running') {
    $('replay-status').textContent = `replaying ${m.name} (frame 0/${m.frames})`;
    log(`replay of ${m.name} (${m.case}, ${m.frames} frames) started`);
  } else {
    $('replay-status').textContent = `live (replay of ${m.name} ${m.ok ? 'ended, every image hash matched' : `failed, exit ${m.exit}`}, frame ${sc.replay.frame} seen)`;
    log(`replay of ${m.name} ended`);
    send({ op: 'sessions' });
  }
}
$('sessions-refresh').onclick = () => send({ op: 'sessions' });

function renderCatalogue(entries) {
  sc.catalogue = entries;
  const ul = $('catalogue');
  ul.replaceChildren(...entries.map((e) => {
    const li = document.createElement('li');
    li.dataset.index = e.index;
    const b = document.createElement('button');
    b.textContent = 'load'; b.dataset.testid = 'case-' + e.index;
    b.onclick = () => send({ op: 'case', id: e.index });
    const h = document.createElement('strong'); h.textContent = ` ${e.name} `;
    const d = document.createElement('div'); d.className = 'desc'; d.textContent = e.description;
    li.append(b, h, d);
    return li;
  }));
}

function connect() {
  ws = new WebSocket(`ws://${location.host}/`, 'sonocomp-console');
  ws.binaryType = 'arraybuffer';
  ws.onopen = () => { $('conn').textContent = 'connected'; };
  ws.onclose = () => { $('conn').textContent = 'disconnected'; setTimeout(connect, 1000); };
  ws.onmessage = (ev) => {
    if (typeof ev.data === 'string') { try { onJson(JSON.parse(ev.data)); } catch (e) { log('bad reply'); } return; }
    const u8 = new Uint8Array(ev.data);
    if (u8[0] === 0x53) onRecord(ev.data);
    else if (u8[0] === 0x42) { sc.bscanBytes = u8.length; onBscan(new DataView(ev.data), u8); }
  };
}
connect();

// imaging: every field at once, as CmdSetImaging carries them
let imgTimer = null;
function imagingChanged() {
  for (const [id, out] of [['gain', 'gain-v'], ['tgc', 'tgc-v'], ['depth', 'depth-v'], ['dr', 'dr-v']]) $(out).textContent = $(id).value;
  clearTimeout(imgTimer);
  imgTimer = setTimeout(() => send({
    op: 'imaging', depth_mm: +$('depth').value, gain_db: +$('gain').value, dyn_range_db: +$('dr').value,
    tgc_db_per_cm: +$('tgc').value, geometry: $('geometry').value,
  }), 150);
}
for (const id of ['gain', 'tgc', 'depth', 'dr', 'geometry']) $(id).addEventListener('input', imagingChanged);
// vessels (CmdVessels) and colour Doppler (CmdDoppler): every field at once, as each carries them
let vesTimer = null, dopTimer = null;
function vesselsChanged() {
  $('hr-v').textContent = $('hr').value;
  $('rr-v').textContent = $('rr').value;
  clearTimeout(vesTimer);
  const rr = +$('rr').value;
  vesTimer = setTimeout(() => send({
    op: 'vessels', heart_rate_bpm: +$('hr').value, resp_rate_bpm: rr < 4 ? 0 : rr,
    valsalva: $('valsalva').getAttribute('aria-pressed') === 'true' ? 1 : 0, pulse: $('pulse').checked ? 1 : 0,
  }), 150);
}
for (const id of ['hr', 'rr', 'pulse']) $(id).addEventListener('input', vesselsChanged);
$('valsalva').onclick = () => {
  const b = $('valsalva');
  b.setAttribute('aria-pressed', b.getAttribute('aria-pressed') === 'true' ? 'false' : 'true');
  vesselsChanged();
};
function dopplerChanged() {
  for (const [id, out] of [['prf', 'prf-v'], ['steer', 'steer-v'], ['cgain', 'cgain-v']]) $(out).textContent = $(id).value;
  clearTimeout(dopTimer);
  dopTimer = setTimeout(() => send({
    op: 'doppler', colour: $('colour').checked ? 'on' : 'off', prf_hz: +$('prf').value,
    steer_deg: +$('steer').value, gain_db: +$('cgain').value,
  }), 150);
}
for (const id of ['colour', 'prf', 'steer', 'cgain']) $(id).addEventListener('input', dopplerChanged);
let methodPendingUntil = 0, pendingMethod = null;
for (const r of document.querySelectorAll('input[name=method]')) {
  r.onchange = () => {
    pendingMethod = r.value;
    methodPendingUntil = performance.now() + 2000;
    send({ op: 'method', value: r.value });
  };
}
for (const b of document.querySelectorAll('[data-reset]')) b.onclick = () => send({ op: 'reset', target: b.dataset.reset });
for (const b of document.querySelectorAll('[data-call]')) b.onclick = () => send({ op: 'assess', action: 'call', call: b.dataset.call });
$('assess-reset').onclick = () => send({ op: 'assess', action: 'reset' });
$('unlock').onclick = () => send({ op: 'auth', pass: $('pass').value });

// ---- Tissue panel: materials per label and the solver's parameters (CmdMaterial) --------------
// The MATERIAL record (type 7, docs/state-stream.md) carries what the running tissue was built
// with; the sliders show it unless the user is holding one, and a release sends the label's E and
// nu with the simulation parameters (the command carries both).
const MAT_LABELS = ['skin', 'fat', 'muscle', 'vein', 'artery', 'nerve', 'thrombus']; // labels 1..7
const matRows = {};
let matHeld = null, matPendingUntil = 0;
const ekpa = (slider) => Math.round(10 ** +slider.value * 10) / 10; // log10 kPa slider
for (const [i, name] of MAT_LABELS.entries()) {
  const row = document.createElement('div');
  row.className = 'matrow';
  const le = document.createElement('label'), ln = document.createElement('label');
  const ov = document.createElement('output'), nv = document.createElement('output');
  const e = document.createElement('input'), nu = document.createElement('input');
  Object.assign(e, { type: 'range', min: -1, max: 3.8, step: 0.01, value: 1 });
  Object.assign(nu, { type: 'range', min: 0, max: 0.49, step: 0.002, value: 0.45 });
  e.dataset.testid = `mat-e-${name}`; nu.dataset.testid = `mat-nu-${name}`;
  ov.dataset.testid = `mat-e-${name}-v`; nv.dataset.testid = `mat-nu-${name}-v`;
  le.append(`${name} E `, ov, ' kPa', e);
  ln.append('ν ', nv, nu);
  row.append(le, ln);
  $('materials').append(row);
  matRows[name] = { label: i + 1, e, nu, ov, nv };
  for (const inp of [e, nu]) {
    inp.addEventListener('pointerdown', () => { matHeld = name; });
    inp.addEventListener('input', () => { matHeld = name; ov.textContent = ekpa(e); nv.textContent = (+nu.value).toFixed(3); });
    inp.addEventListener('change', () => sendMaterial(name)); // on release
  }
}
function simParams() {
  return { damping_s: +(+$('mat-damping').value).toFixed(3), cg_iterations: +$('mat-cg').value,
           corotated: $('mat-corotated').checked ? 1 : 0 };
}
function sendMaterial(name) {
  const r = matRows[name];
  matHeld = null;
  matPendingUntil = performance.now() + 3000; // until the rebuilt tissue's record shows it
  send({ op: 'material', label: name, e_kpa: ekpa(r.e), nu: +(+r.nu.value).toFixed(3), ...simParams() });
}
// the simulation parameters travel with a label: the last one moved, else fat (its values as shown)
let matLast = 'fat';
for (const id of ['mat-damping', 'mat-cg', 'mat-corotated']) {
  const el = $(id);
  el.addEventListener('pointerdown', () => { matHeld = id; });
  el.addEventListener('input', () => {
    matHeld = id;
    $('mat-damping-v').textContent = (+$('mat-damping').value).toFixed(3);
    $('mat-cg-v').textContent = $('mat-cg').value;
  });
  el.addEventListener('change', () => sendMaterial(matLast));
}
for (const name of MAT_LABELS) matRows[name].e.addEventListener('change', () => { matLast = name; });

function onMaterial(dv, p) {
  if (dv.byteLength < p + 160) return;
  const n = dv.getUint8(p), rows = {};
  for (let l = 0; l < n && l < 16; l++) rows[l] = { e: dv.getFloat32(p + 32 + 8 * l, true), nu: dv.getFloat32(p + 36 + 8 * l, true) };
  const m = {
    count: n, simOverride: dv.getUint8(p + 1) === 1, cgIterations: dv.getUint8(p + 2), corotated: dv.getUint8(p + 3),
    dampingS: dv.getFloat32(p + 4, true), mask: dv.getUint32(p + 8, true),
    rebuilds: Number(dv.getBigUint64(p + 16, true)), refused: Number(dv.getBigUint64(p + 24, true)),
    rows, labels: {},
  };
  for (const name of MAT_LABELS) {
    const r = rows[matRows[name].label];
    if (r) m.labels[name] = { eKpa: r.e / 1000, nu: r.nu, overridden: (m.mask >> matRows[name].label) & 1 };
  }
  const changed = !sc.material || sc.material.rebuilds !== m.rebuilds;
  sc.material = m;
  if (changed) matPendingUntil = 0; // the rebuilt tissue: show what it holds
  const over = MAT_LABELS.filter((name) => m.labels[name]?.overridden);
  const busy = sc.frame && sc.frame.switching;
  $('tissue-status').textContent = `${over.length ? 'set: ' + over.join(', ') : "the case's own materials"}` +
    `${m.simOverride ? '; simulation parameters set' : ''}; ${m.rebuilds} rebuilds, ${m.refused} refused${busy ? '; rebuilding…' : ''}`;
  if (performance.now() < matPendingUntil) return;
  for (const name of MAT_LABELS) {
    const r = matRows[name], v = m.labels[name];
    if (!v || matHeld === name) continue;
    r.e.value = Math.log10(Math.max(v.eKpa, 0.1)).toFixed(2);
    r.nu.value = v.nu;
    r.ov.textContent = v.eKpa >= 100 ? v.eKpa.toFixed(0) : v.eKpa.toPrecision(3);
    r.nv.textContent = v.nu.toFixed(3);
    r.e.title = r.nu.title = v.overridden ? 'set by CmdMaterial' : "the case's value";
    r.e.parentElement.parentElement.classList.toggle('overridden', !!v.overridden);
  }
  if (!String(matHeld).startsWith('mat-')) {
    $('mat-damping').value = m.dampingS; $('mat-damping-v').textContent = m.dampingS.toFixed(3);
    $('mat-cg').value = m.cgIterations; $('mat-cg-v').textContent = m.cgIterations;
    $('mat-corotated').checked = m.corotated === 1;
  }
}
