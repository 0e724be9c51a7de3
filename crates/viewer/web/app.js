// The animats live view: draws the world the server streams over /ws with
// three.js, and sends the controls back. Protocol: crates/viewer/src/protocol.rs.
import * as THREE from 'three';
import { OrbitControls } from '/vendor/OrbitControls.js';

// What is drawn comes from the server (the renderer draws the same
// `drawing`): each ball's radius, colour and look, each rod's radius and
// colour, each bell's shape every frame, the floor's checker and the water.
// The page computes no shape of its own.
const WATER = 0x0d3b5c;
const AIR = 0xbfd4e6;

const $ = (id) => document.getElementById(id);
const canvas = $('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
renderer.shadowMap.enabled = true;
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(50, 1, 0.005, 2000);
const controls = new OrbitControls(camera, canvas);
controls.enableDamping = true;
controls.addEventListener('start', () => { controls.autoRotate = false; });
scene.add(new THREE.HemisphereLight(0xe8f0ff, 0x4a3f30, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(3, 8, 5);
sun.castShadow = true;
sun.shadow.mapSize.set(1024, 1024);
scene.add(sun);
scene.add(sun.target);

/** Keeps the sun's shadow box around what the camera looks at. */
function aimSun(size) {
  const t = controls.target;
  sun.target.position.copy(t);
  sun.position.set(t.x + 0.3 * size, t.y + size, t.z + 0.5 * size);
  const c = sun.shadow.camera;
  c.left = c.bottom = -size;
  c.right = c.top = size;
  c.near = 0.01;
  c.far = 4 * size;
  c.updateProjectionMatrix();
}

const sphere = new THREE.SphereGeometry(1, 20, 14);
const rod = new THREE.CylinderGeometry(1, 1, 1, 8, 1);
// The bell: the upper half of a unit sphere, its rim on y = 0.
const bell = new THREE.SphereGeometry(1, 28, 10, 0, 2 * Math.PI, 0, Math.PI / 2);

// What the page knows; the browser test reads it.
const viewer = {
  scene: null, frame: null, frames: 0, arrivals: [], connected: false,
  send, project, floorHit,
};
window.__viewer = viewer;

let socket = null;
let drawn = null; // the three.js objects of the current scene
let pending = null; // newest frame not yet drawn
let framed = null; // title of the scene the camera was framed for

function send(command) {
  if (socket && socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify(command));
}

function connect() {
  // The access token the page was opened with (required off the loopback
  // address), passed on to the WebSocket.
  const token = new URLSearchParams(location.search).get('token');
  const query = token ? `?token=${encodeURIComponent(token)}` : '';
  const url = `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws${query}`;
  socket = new WebSocket(url);
  socket.onopen = () => { viewer.connected = true; $('status').textContent = 'live'; };
  socket.onclose = () => {
    viewer.connected = false;
    $('status').textContent = 'disconnected: retrying';
    setTimeout(connect, 1000);
  };
  socket.onmessage = (event) => {
    let msg;
    try { msg = JSON.parse(event.data); } catch { return; }
    if (msg.type === 'scene') {
      viewer.scene = msg;
      build(msg);
    } else if (msg.type === 'frame') {
      viewer.frame = msg;
      viewer.frames += 1;
      const now = performance.now();
      viewer.arrivals.push(now);
      while (viewer.arrivals.length > 0 && viewer.arrivals[0] < now - 3000) viewer.arrivals.shift();
      pending = msg;
    }
  };
}

function material(colour, look) {
  const m = new THREE.MeshStandardMaterial({ color: colour, roughness: 0.6, metalness: 0.05 });
  if (look === 'glow') m.emissive = new THREE.Color(0x664400);
  if (look === 'clear') { m.transparent = true; m.opacity = 0.55; m.roughness = 0.1; }
  if (look === 'soft') { m.transparent = true; m.opacity = 0.85; }
  return m;
}

function build(desc) {
  if (drawn) {
    scene.remove(drawn.group);
    drawn.group.traverse((o) => {
      if (o.material) {
        if (o.material.map) o.material.map.dispose();
        o.material.dispose();
      }
    });
  }
  const group = new THREE.Group();
  const d = desc.drawing;
  const water = d.water;
  scene.background = new THREE.Color(water ? WATER : AIR);
  scene.fog = water ? new THREE.FogExp2(WATER, 0.18) : new THREE.Fog(AIR, 30, 120);

  let floor = null;
  if (d.floor !== null) {
    // A checkerboard shows scale and motion.
    const cell = d.floor;
    const size = cell * 400;
    const [a, b] = water ? [[194, 178, 128], [178, 162, 114]] : [[150, 168, 128], [128, 146, 108]];
    const texels = new Uint8Array([...a, 255, ...b, 255, ...b, 255, ...a, 255]);
    const checker = new THREE.DataTexture(texels, 2, 2);
    checker.colorSpace = THREE.SRGBColorSpace;
    checker.wrapS = checker.wrapT = THREE.RepeatWrapping;
    checker.magFilter = THREE.NearestFilter;
    checker.minFilter = THREE.LinearMipmapLinearFilter;
    checker.generateMipmaps = true;
    if (d.ground) {
      // Terrain: the server's triangles, the checker laid on x and z.
      const geometry = new THREE.BufferGeometry();
      const p = d.ground.positions;
      const uv = new Float32Array((p.length / 3) * 2);
      for (let k = 0; k < p.length / 3; k++) {
        uv[2 * k] = p[3 * k] / cell / 2;
        uv[2 * k + 1] = -p[3 * k + 2] / cell / 2;
      }
      geometry.setAttribute('position', new THREE.Float32BufferAttribute(p, 3));
      geometry.setAttribute('uv', new THREE.Float32BufferAttribute(uv, 2));
      geometry.setIndex(d.ground.triangles);
      geometry.computeVertexNormals();
      floor = new THREE.Mesh(
        geometry,
        new THREE.MeshStandardMaterial({ map: checker, roughness: 0.95, flatShading: true, side: THREE.DoubleSide }),
      );
    } else {
      checker.repeat.set(size / cell / 2, size / cell / 2);
      floor = new THREE.Mesh(
        new THREE.PlaneGeometry(size, size),
        new THREE.MeshStandardMaterial({ map: checker, roughness: 0.95 }),
      );
      floor.rotation.x = -Math.PI / 2;
    }
    checker.needsUpdate = true;
    floor.receiveShadow = true;
    group.add(floor);
  }

  // Balls, one instanced mesh per colour and look.
  const groups = new Map();
  d.balls.forEach((b, i) => {
    const key = `${b.colour}/${b.look}/${b.shadow}`;
    if (!groups.has(key)) groups.set(key, { ball: b, indices: [] });
    groups.get(key).indices.push(i);
  });
  const spheres = [];
  for (const { ball, indices } of groups.values()) {
    const mesh = new THREE.InstancedMesh(sphere, material(ball.colour, ball.look), indices.length);
    mesh.frustumCulled = false;
    mesh.castShadow = ball.shadow;
    group.add(mesh);
    spheres.push({ mesh, indices, radii: indices.map((i) => d.balls[i].radius) });
  }

  // Springs as thin rods.
  let springs = null;
  if (d.rods.length > 0) {
    const mesh = new THREE.InstancedMesh(rod, new THREE.MeshStandardMaterial({ roughness: 0.7 }), d.rods.length);
    mesh.frustumCulled = false;
    mesh.castShadow = true;
    const colour = new THREE.Color();
    d.rods.forEach((r, k) => mesh.setColorAt(k, colour.setHex(r.colour)));
    group.add(mesh);
    springs = { mesh, rods: d.rods };
  }

  // Joints as axles through their joint particle, placed by the server
  // every frame; a motor coloured by its actuator's level.
  let axles = null;
  if ((d.axles ?? []).length > 0) {
    const mesh = new THREE.InstancedMesh(rod, new THREE.MeshStandardMaterial({ roughness: 0.35, metalness: 0.5 }), d.axles.length);
    mesh.frustumCulled = false;
    mesh.castShadow = true;
    const colour = new THREE.Color();
    d.axles.forEach((x, k) => mesh.setColorAt(k, colour.setHex(x.colour)));
    group.add(mesh);
    axles = { mesh, radii: d.axles.map((x) => x.radius) };
  }
  viewer.axles = axles ? d.axles.length : 0;
  viewer.axlesPlaced = 0;

  // Jellyfish: translucent bells over their dome masses, shaped by the
  // server every frame.
  const domes = d.bells.map((b) => {
    const mesh = new THREE.Mesh(bell, new THREE.MeshStandardMaterial({
      color: b.colour, transparent: true, opacity: 0.45, side: THREE.DoubleSide, roughness: 0.3,
      emissive: 0x301020,
    }));
    mesh.frustumCulled = false;
    mesh.visible = false;
    group.add(mesh);
    return { mesh };
  });

  scene.add(group);
  // Captions over the 3-D view (an evolution's lanes), placed every frame.
  const box = $('labels');
  box.replaceChildren();
  const labels = (desc.labels ?? []).map((l) => {
    const div = document.createElement('div');
    div.className = 'label';
    div.textContent = l.text;
    box.appendChild(div);
    return { div, particle: l.particle, lift: 3 * desc.drawing.balls[l.particle].radius + 0.05 };
  });
  drawn = { group, spheres, springs, axles, domes, floor, water, labels, size: desc.distance };
  viewer.groundTriangles = d.ground ? floor.geometry.index.count / 3 : 0;

  // Depth precision: the near plane scales with the scene, or the grid
  // flickers into the floor.
  camera.near = Math.max(0.001, desc.distance / 400);
  camera.far = Math.max(100, desc.distance * 300);
  camera.updateProjectionMatrix();
  $('hint').textContent = 'drag: orbit · right-drag: pan · wheel: zoom'
    + (desc.food !== null ? ' · click the floor: move the food' : '')
    + ' · space: pause · s: step · r: reset';
  if (framed !== desc.title) {
    framed = desc.title;
    const [x, y, z] = desc.target;
    controls.target.set(x, y, z);
    const dir = new THREE.Vector3(0.55, 0.45, 1.0).normalize();
    camera.position.set(x, y, z).addScaledVector(dir, desc.distance);
    controls.update();
  }
  $('title').textContent = desc.title;
  $('followbox').style.display = 'none';
}

const m4 = new THREE.Matrix4();
const q = new THREE.Quaternion();
const v = new THREE.Vector3();
const w = new THREE.Vector3();
const s3 = new THREE.Vector3();
const UP = new THREE.Vector3(0, 1, 0);
const ONE = new THREE.Quaternion();
const tint = new THREE.Color();

function at(p, i, out) { return out.set(p[3 * i] ?? 0, p[3 * i + 1] ?? 0, p[3 * i + 2] ?? 0); }

function draw(frame) {
  const p = frame.p;
  for (const { mesh, indices, radii } of drawn.spheres) {
    indices.forEach((i, j) => {
      at(p, i, v);
      s3.setScalar(radii[j]);
      mesh.setMatrixAt(j, m4.compose(v, ONE, s3));
    });
    mesh.instanceMatrix.needsUpdate = true;
  }
  if (drawn.springs) {
    const { mesh, rods } = drawn.springs;
    rods.forEach((r, k) => {
      at(p, r.a, v);
      at(p, r.b, w);
      const length = v.distanceTo(w);
      w.sub(v);
      if (length > 1e-9) q.setFromUnitVectors(UP, w.divideScalar(length)); else q.identity();
      v.addScaledVector(w, 0.5 * length);
      s3.set(r.radius, Math.max(length, 1e-6), r.radius);
      mesh.setMatrixAt(k, m4.compose(v, q, s3));
    });
    mesh.instanceMatrix.needsUpdate = true;
    // Muscles coloured by their activation now (the server's colours).
    if (frame.rods && frame.rods.length === rods.length) {
      frame.rods.forEach((c, k) => mesh.setColorAt(k, tint.setHex(c)));
      if (mesh.instanceColor) mesh.instanceColor.needsUpdate = true;
    }
  }
  if (drawn.axles && (frame.axles ?? []).length === drawn.axles.radii.length) {
    const { mesh, radii } = drawn.axles;
    frame.axles.forEach(([a, b], k) => {
      v.set(...a);
      w.set(...b);
      const length = v.distanceTo(w);
      w.sub(v);
      if (length > 1e-9) q.setFromUnitVectors(UP, w.divideScalar(length)); else q.identity();
      v.addScaledVector(w, 0.5 * length);
      s3.set(radii[k], Math.max(length, 1e-6), radii[k]);
      mesh.setMatrixAt(k, m4.compose(v, q, s3));
    });
    mesh.instanceMatrix.needsUpdate = true;
    viewer.axlesPlaced = frame.axles.length;
    if ((frame.axle_colours ?? []).length === radii.length) {
      frame.axle_colours.forEach((c, k) => mesh.setColorAt(k, tint.setHex(c)));
      if (mesh.instanceColor) mesh.instanceColor.needsUpdate = true;
    }
  }
  drawn.domes.forEach((d, k) => {
    const b = (frame.bells ?? [])[k];
    d.mesh.visible = !!b;
    if (!b) return;
    d.mesh.position.set(...b.centre);
    d.mesh.quaternion.setFromUnitVectors(UP, v.set(...b.axis));
    d.mesh.scale.set(b.radius, b.height, b.radius);
  });
  if (frame.focus && $('follow').checked) {
    const target = new THREE.Vector3(...frame.focus);
    // An evolution's leader changes: ease over; a walker is tracked closely.
    const shift = target.sub(controls.target).multiplyScalar(viewer.scene.orbit ? 0.08 : 0.3);
    controls.target.add(shift);
    camera.position.add(shift);
  }
  overlay(frame);
}

function overlay(frame) {
  const now = performance.now();
  const recent = viewer.arrivals.filter((t) => t > now - 1000).length;
  const lines = [
    `t        ${frame.t.toFixed(2)} s${frame.paused ? '  (paused)' : ''}`,
    `frames   ${frame.fps.toFixed(1)}/s sent, ${recent}/s here`,
    `rtf      ${frame.rtf.toFixed(2)} × real time` + (frame.speed > 0 ? ` (asked ${frame.speed}×)` : ' (flat out)'),
  ];
  $('stats').textContent = lines.join('\n');
  $('note').textContent = frame.note ?? '';
  $('pause').textContent = frame.paused ? 'resume' : 'pause';
  $('followbox').style.display = frame.focus ? '' : 'none';
  const err = $('error');
  err.style.display = frame.error ? 'block' : 'none';
  err.textContent = frame.error ?? '';
  const list = $('creatures');
  const html = frame.creatures.map((c) => {
    const energy = c.energy == null ? ''
      : `<span title="energy ${c.energy.toFixed(2)}"><span class="bar"><i style="width:${(100 * Math.min(1, Math.max(0, c.energy))).toFixed(0)}%"></i></span> ${c.energy.toFixed(2)}</span>`;
    return `<div class="creature" data-name="${escape(c.name)}"><span>${escape(c.name)}</span><span class="state state-${escape(c.state)}">${escape(c.state)}</span>${energy}</div>`;
  }).join('');
  if (list.innerHTML !== html) list.innerHTML = html;
}

function escape(s) {
  return String(s).replace(/[&<>"']/g, (c) => `&#${c.charCodeAt(0)};`);
}

function resize() {
  const width = window.innerWidth;
  const height = window.innerHeight;
  renderer.setSize(width, height, false);
  camera.aspect = width / height;
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', resize);
resize();

/** Where world point (x, y, z) appears on the page, in CSS pixels. */
function project(x, y, z) {
  const p = new THREE.Vector3(x, y, z).project(camera);
  const r = canvas.getBoundingClientRect();
  return { x: r.left + (p.x + 1) / 2 * r.width, y: r.top + (1 - p.y) / 2 * r.height, visible: p.z < 1 };
}

/** Where a click at page pixel (px, py) meets the floor (or, with no floor, the food's level). */
function floorHit(px, py) {
  const r = canvas.getBoundingClientRect();
  const ndc = new THREE.Vector2((px - r.left) / r.width * 2 - 1, -((py - r.top) / r.height) * 2 + 1);
  const ray = new THREE.Raycaster();
  ray.setFromCamera(ndc, camera);
  let level = 0;
  if (!viewer.scene.floor && viewer.scene.food !== null && viewer.frame) level = viewer.frame.p[3 * viewer.scene.food + 1];
  const hit = new THREE.Vector3();
  return ray.ray.intersectPlane(new THREE.Plane(new THREE.Vector3(0, 1, 0), -level), hit) ? hit : null;
}

// A click (not a drag) on the floor moves the food.
let down = null;
canvas.addEventListener('pointerdown', (e) => { down = { x: e.clientX, y: e.clientY }; });
canvas.addEventListener('pointerup', (e) => {
  if (!down || e.button !== 0) return;
  const moved = Math.hypot(e.clientX - down.x, e.clientY - down.y);
  down = null;
  if (moved > 4 || !viewer.scene || viewer.scene.food === null) return;
  const hit = floorHit(e.clientX, e.clientY);
  if (hit) send({ cmd: 'food', x: hit.x, z: hit.z });
});

$('pause').addEventListener('click', () => send({ cmd: viewer.frame && viewer.frame.paused ? 'resume' : 'pause' }));
$('step').addEventListener('click', () => send({ cmd: 'step' }));
$('reset').addEventListener('click', () => send({ cmd: 'reset' }));
$('speed').addEventListener('change', (e) => send({ cmd: 'speed', value: Number(e.target.value) }));
window.addEventListener('keydown', (e) => {
  if (e.target.tagName === 'SELECT') return;
  if (e.key === ' ') { $('pause').click(); e.preventDefault(); }
  if (e.key === 's') send({ cmd: 'step' });
  if (e.key === 'r') send({ cmd: 'reset' });
});

function animate() {
  requestAnimationFrame(animate);
  if (pending && drawn) {
    // An evolution is shown as the thesis did: the camera orbits the
    // leader until the user takes over.
    if (pending.focus && viewer.scene.orbit && !viewer.orbited) { viewer.orbited = true; controls.autoRotate = true; }
    draw(pending);
    pending = null;
  }
  controls.update();
  if (drawn) aimSun(drawn.size);
  renderer.render(scene, camera);
  if (drawn && viewer.frame) placeLabels(viewer.frame.p);
}

/** Puts each caption above its particle, as the camera sees it now. */
function placeLabels(p) {
  for (const l of drawn.labels) {
    const i = 3 * l.particle;
    const at = project(p[i], p[i + 1] + l.lift, p[i + 2]);
    l.div.style.display = at.visible ? '' : 'none';
    l.div.style.left = `${at.x.toFixed(1)}px`;
    l.div.style.top = `${at.y.toFixed(1)}px`;
  }
}
controls.autoRotateSpeed = 0.6;
connect();
animate();
