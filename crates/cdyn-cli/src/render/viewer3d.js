// ---------- a spatial mechanism in 3-D ----------
// The page's own small renderer (no library: the page stays one small file
// that fetches nothing): perspective on the 2-D canvas, the bodies' solids
// shaded and painted far to near with back faces dropped, then the
// skeleton on top. The scene (solids in body axes, the sphere around the
// run) comes from scene3d.rs; gif3d.rs draws the GIF's frames the same way.
// Drag orbits, the wheel zooms, a double click goes back to the start view;
// "#yaw=…&pitch=…" (degrees) and "#zoom=…" set the view.

const VIEW0 = { yaw: -0.95054684, pitch: 0.4354940, zoom: 1 };
const cam3 = Object.assign({}, VIEW0);
const HALF_FIELD = 20 * Math.PI / 180, DISTANCE = 3;

/** A(p) s: body axes to space for Euler parameters p (scalar first). */
function rotate3(p, s) {
  const [e0, e1, e2, e3] = p, e = [e1, e2, e3];
  const sc = e0 * e0 - (e1 * e1 + e2 * e2 + e3 * e3), es = e1 * s[0] + e2 * s[1] + e3 * s[2];
  const cr = [e2 * s[2] - e3 * s[1], e3 * s[0] - e1 * s[2], e1 * s[1] - e2 * s[0]];
  return [0, 1, 2].map((i) => s[i] * sc + 2 * e[i] * es + 2 * e0 * cr[i]);
}
const dot3 = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];

/** The camera of the current view: orbiting the scene's centre, z up. */
function camera3() {
  const { yaw, pitch, zoom } = cam3;
  const back = [Math.cos(pitch) * Math.cos(yaw), Math.cos(pitch) * Math.sin(yaw), Math.sin(pitch)];
  const right = [-Math.sin(yaw), Math.cos(yaw), 0];
  const up = [back[1] * right[2] - back[2] * right[1], back[2] * right[0] - back[0] * right[2], back[0] * right[1] - back[1] * right[0]];
  const d = DISTANCE * sketch.radius / zoom;
  const eye = [0, 1, 2].map((i) => sketch.centre[i] + d * back[i]);
  const light = [0, 1, 2].map((i) => back[i] + 0.6 * up[i] + 0.3 * right[i]);
  const ln = Math.hypot(...light);
  return { eye, right, up, back, light: light.map((x) => x / ln), focal: 0.5 * Math.min(scene.width, scene.height) / Math.tan(HALF_FIELD), mid: [scene.width / 2, scene.height / 2] };
}
/** [pixel, depth] of the space point p. */
function project3(cam, p) {
  const d = [p[0] - cam.eye[0], p[1] - cam.eye[1], p[2] - cam.eye[2]];
  const depth = -dot3(d, cam.back), z = Math.max(depth, 1e-9);
  return [[cam.mid[0] + cam.focal * dot3(d, cam.right) / z, cam.mid[1] - cam.focal * dot3(d, cam.up) / z], depth];
}
/** A body's pose in q: position and Euler parameters. */
const pose3 = (b, q) => [q.slice(b.first, b.first + 3), q.slice(b.first + 3, b.first + 7)];
/** Where anchor a (a body point or a ground point) is at positions q. */
function place3(a, q) {
  if (a.body == null) return a.point;
  const [r, p] = pose3(sketch.bodies[a.body], q), x = rotate3(p, a.point);
  return [r[0] + x[0], r[1] + x[1], r[2] + x[2]];
}
/** "#rrggbb" lit by l (0 … 1). */
function shade3(hex, l) {
  const c = [1, 3, 5].map((i) => Math.round(Math.min(255, parseInt(hex.slice(i, i + 2), 16) * l)));
  return "rgb(" + c.join(",") + ")";
}

/** Draws frame k of case c in 3-D; returns the bodies' centres of mass in canvas pixels. */
function drawFrame3d(c, k) {
  const cs = cases[c], q = cs.frames.q[k], cam = camera3();
  const px = (p) => project3(cam, p)[0];
  ctx.fillStyle = "#fff"; ctx.fillRect(0, 0, scene.width, scene.height);
  ctx.fillStyle = "#333"; ctx.font = "12px sans-serif";
  ctx.fillText("t = " + fmt(cs.frames.t[k], 4), 8, 16);
  if (q.some((x) => !isFinite(x))) { ctx.fillText("positions not finite", 8, 32); return []; }
  for (const [a, b] of sketch.grid) line(px(a), px(b), "#ddd", 1);
  // The solids, far to near, faces turned away dropped; the ground's (a robot's base) grey, in space.
  const paints = [];
  const solids = sketch.bodies.map((b, i) => [b, pose3(b, q), bodyColour(i)]);
  solids.push([sketch.ground, [[0, 0, 0], [1, 0, 0, 0]], "#aaaaaa"]);
  solids.forEach(([b, [r, p], colour]) => {
    const to = (x) => { const y = rotate3(p, x); return [r[0] + y[0], r[1] + y[1], r[2] + y[2]]; };
    for (const f of b.faces) {
      const corners = f.corners.map(to), n = rotate3(p, f.normal);
      if (dot3(n, [0, 1, 2].map((j) => cam.eye[j] - corners[0][j])) <= 0) continue;
      const pr = corners.map((x) => project3(cam, x));
      const depth = pr.reduce((s, x) => s + x[1], 0) / pr.length;
      paints.push({ depth, face: pr.map((x) => x[0]), colour: shade3(colour, 0.45 + 0.55 * Math.abs(dot3(n, cam.light))) });
    }
    for (const s of b.spheres) {
      const [centre, depth] = project3(cam, to(s.centre));
      paints.push({ depth, ball: centre, radius: Math.max(1, cam.focal * s.radius / Math.max(depth, 1e-9)), colour: shade3(colour, 0.85) });
    }
  });
  paints.sort((a, b) => b.depth - a.depth);
  ctx.lineWidth = 1; ctx.setLineDash([]);
  for (const x of paints) {
    ctx.beginPath();
    if (x.face) { x.face.forEach((p, j) => (j ? ctx.lineTo(p[0], p[1]) : ctx.moveTo(p[0], p[1]))); ctx.closePath(); }
    else ctx.arc(x.ball[0], x.ball[1], x.radius, 0, 2 * Math.PI);
    ctx.fillStyle = x.colour; ctx.fill(); ctx.strokeStyle = "rgba(0,0,0,0.25)"; ctx.stroke();
  }
  // The skeleton on top: centre of mass to joint points, rods, joints, ground points, body axes.
  sketch.bodies.forEach((b, i) => {
    const c0 = px(pose3(b, q)[0]);
    for (const pt of b.points) line(c0, px(place3({ body: i, point: pt }, q)), "#333", 2);
  });
  for (const ends of sketch.joints) {
    const p = ends.map((e) => px(place3(e, q)));
    if (Math.hypot(p[0][0] - p[1][0], p[0][1] - p[1][1]) > 0.5) line(p[0], p[1], "#000", 2);
    ends.forEach((e, j) => { if (e.body == null) { ctx.fillStyle = "#000"; ctx.fillRect(p[j][0] - 4, p[j][1] - 4, 8, 8); } });
    disc(p[0], 4, "#fff", "#000");
  }
  return sketch.bodies.map((b, i) => {
    const [r, p] = pose3(b, q), c0 = px(r);
    ["#f00", "#0a0", "#00f"].forEach((colour, j) => {
      const u = [0, 0, 0]; u[j] = sketch.axis;
      const d = rotate3(p, u);
      line(c0, px([r[0] + d[0], r[1] + d[1], r[2] + d[2]]), colour, 2);
    });
    disc(c0, 5, bodyColour(i), "#000");
    return c0;
  });
}

/** Orbit (drag), zoom (wheel), start view (double click), and the view from the address's "#yaw=&pitch=&zoom=". */
function setView3d(hash) {
  const deg = Math.PI / 180;
  if (hash.has("yaw")) cam3.yaw = Number(hash.get("yaw")) * deg || 0;
  if (hash.has("pitch")) cam3.pitch = Math.max(-89, Math.min(89, Number(hash.get("pitch")) || 0)) * deg;
  if (hash.has("zoom")) cam3.zoom = Math.max(0.1, Math.min(20, Number(hash.get("zoom")) || 1));
  let drag = null;
  scene.addEventListener("pointerdown", (e) => { drag = [e.clientX, e.clientY]; scene.setPointerCapture(e.pointerId); });
  scene.addEventListener("pointerup", () => { drag = null; });
  scene.addEventListener("pointermove", (e) => {
    if (!drag) return;
    cam3.yaw -= 0.01 * (e.clientX - drag[0]);
    cam3.pitch = Math.max(-1.55, Math.min(1.55, cam3.pitch + 0.01 * (e.clientY - drag[1])));
    drag = [e.clientX, e.clientY];
    show(state.time);
  });
  scene.addEventListener("wheel", (e) => { e.preventDefault(); cam3.zoom = Math.max(0.1, Math.min(20, cam3.zoom * Math.exp(-0.001 * e.deltaY))); show(state.time); }, { passive: false });
  scene.addEventListener("dblclick", () => { Object.assign(cam3, VIEW0); show(state.time); });
  scene.style.cursor = "grab";
  const drawn = sketch.bodies.filter((b) => !b.shaped).map((b) => b.name);
  $("view3d").hidden = false;
  $("view3d").textContent = "3-D, perspective, z up: drag to orbit, wheel to zoom, double click for the start view. Bodies as their URDF boxes, cylinders and spheres" +
    (drawn.length ? "; " + drawn.join(", ") + " as the box of uniform density with its inertia" : "") +
    (sketch.ground.faces.length + sketch.ground.spheres.length ? "; the ground's parts (a base) grey" : "") +
    "; a dark line from each centre of mass to each joint point, joints as white rings, ground points as black squares, body axes x red, y green, z blue.";
}
