// The three.js viewer: ground-truth mesh, reconstruction points, crop box / sphere gizmo,
// point picking. Everything is drawn in the ground-truth frame, shifted by `offset` so that
// large coordinates keep their float32 precision on the GPU.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { TransformControls } from 'three/addons/controls/TransformControls.js';

/** Most reconstruction points drawn; a denser cloud is drawn every k-th point. */
export const MAX_DRAWN_POINTS = 2_000_000;

export class Viewer {
  constructor(container) {
    this.container = container;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.setClearColor(0x1d2128);
    this.renderer.domElement.id = 'view3d';
    container.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(45, 1, 0.001, 1000);
    this.camera.position.set(2, 1.5, 3);
    this.world = new THREE.Group();
    this.scene.add(this.world);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x445566, 1.2));
    const sun = new THREE.DirectionalLight(0xffffff, 1.5);
    sun.position.set(3, 5, 4);
    this.scene.add(sun);
    this.orbit = new OrbitControls(this.camera, this.renderer.domElement);
    this.orbit.enableDamping = false;
    this.gizmo = new TransformControls(this.camera, this.renderer.domElement);
    this.gizmo.addEventListener('dragging-changed', (e) => { this.orbit.enabled = !e.value; });
    this.gizmo.addEventListener('objectChange', () => { if (this.onCropChange) this.onCropChange(); });
    this.scene.add(this.gizmo.getHelper ? this.gizmo.getHelper() : this.gizmo);
    this.pointSize = 3;
    this.gtMesh = null;
    this.points = null;
    this.cropObject = null;
    this.pairMarkers = new THREE.Group();
    this.world.add(this.pairMarkers);
    this.diag = 1;
    this.raycaster = new THREE.Raycaster();
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
    // Drawn on demand, in the next animation frame after a change, never in a loop: an idle
    // page that redraws every frame keeps a core busy (the GPU, or the CPU under a software
    // renderer) and takes it from the evaluation's workers. Changes come from the controls'
    // events and from every method of this class (wrapped below).
    this.renderQueued = false;
    this.orbit.addEventListener('change', () => this.requestRender());
    this.gizmo.addEventListener('change', () => this.requestRender());
    for (const name of Object.getOwnPropertyNames(Viewer.prototype)) {
      const f = this[name];
      if (name === 'constructor' || name === 'requestRender' || typeof f !== 'function') continue;
      this[name] = (...args) => {
        const out = f.apply(this, args);
        this.requestRender();
        return out;
      };
    }
    this.requestRender();
    this.renderer.domElement.addEventListener('pointerdown', (e) => { this.down = [e.clientX, e.clientY]; });
    this.renderer.domElement.addEventListener('pointerup', (e) => {
      if (!this.down || !this.onPick) return;
      const moved = Math.hypot(e.clientX - this.down[0], e.clientY - this.down[1]);
      if (moved < 4) this.pick(e);
    });
  }

  resize() {
    // the page's viewer shares its box with a second one when comparing side by side
    const w = (this.container.classList.contains('split') ? 0.5 : 1) * (this.container.clientWidth || 300);
    const h = this.container.clientHeight || 300;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
  }

  /** Sets the ground-truth geometry (Float32Array vertices, Uint32Array triangles). */
  setGroundTruth(vertices, triangles, bounds) {
    if (this.gtMesh) { this.world.remove(this.gtMesh); this.gtMesh.geometry.dispose(); }
    const c = [0, 1, 2].map((k) => (bounds[k] + bounds[k + 3]) / 2);
    this.offset = c;
    this.world.position.set(-c[0], -c[1], -c[2]);
    this.diag = Math.hypot(bounds[3] - bounds[0], bounds[4] - bounds[1], bounds[5] - bounds[2]) || 1;
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(vertices, 3));
    let obj;
    if (triangles.length) {
      g.setIndex(new THREE.BufferAttribute(triangles, 1));
      g.computeVertexNormals();
      obj = new THREE.Mesh(g, new THREE.MeshStandardMaterial({
        color: 0xb8c4d0, roughness: 0.8, metalness: 0.0, side: THREE.DoubleSide,
        transparent: true, opacity: 0.85,
      }));
    } else {
      obj = new THREE.Points(g, new THREE.PointsMaterial({ color: 0xb8c4d0, size: this.pointSize, sizeAttenuation: false }));
    }
    obj.name = 'gt';
    this.gtMesh = obj;
    this.world.add(obj);
    this.fit();
  }

  /** Removes the ground truth (after a failed load: nothing stale stays on screen). */
  clearGroundTruth() {
    if (this.gtMesh) { this.world.remove(this.gtMesh); this.gtMesh.geometry.dispose(); this.gtMesh = null; }
  }

  /** Removes the reconstruction's points and the pair markers. */
  clearPoints() {
    if (this.points) { this.world.remove(this.points); this.points.geometry.dispose(); this.points = null; }
    this.pairMarkers.clear();
  }

  /** Frames the ground truth; `wide` also frames the space beside it (the "before" view). */
  fit(wide = false) {
    const d = this.diag;
    const cx = wide ? 0.45 * d : 0;
    const k = wide ? 1.6 : 1;
    this.camera.near = d / 1000;
    this.camera.far = d * 100;
    this.camera.position.set(cx + 0.9 * d * k, 0.6 * d * k, 1.2 * d * k);
    this.camera.updateProjectionMatrix();
    this.orbit.target.set(cx, 0, 0);
    this.orbit.update();
  }

  /**
   * Sets the points to show (x, y, z in the GT frame: Float32Array or Float64Array) with RGB
   * colours (Uint8Array or null). Past MAX_DRAWN_POINTS every k-th point is drawn (the fewest k
   * that fit): uploading and drawing a dense cloud whole froze the page for about 0.8 s at 10M
   * points (software WebGL) and shows nothing more on a canvas of a few million pixels. A pick
   * still names the point's index in the whole cloud; `drawn` says what is on screen.
   */
  setPoints(positions, colors) {
    if (this.points) { this.world.remove(this.points); this.points.geometry.dispose(); }
    const total = positions.length / 3;
    const stride = Math.max(1, Math.ceil(total / MAX_DRAWN_POINTS));
    const count = Math.ceil(total / stride);
    let xyz = positions, rgb = colors;
    if (stride > 1 || !(positions instanceof Float32Array)) {
      xyz = new Float32Array(3 * count);
      rgb = colors ? new Uint8Array(3 * count) : null;
      for (let j = 0, i = 0; j < count; j++, i += 3 * stride) {
        xyz[3 * j] = positions[i]; xyz[3 * j + 1] = positions[i + 1]; xyz[3 * j + 2] = positions[i + 2];
        if (rgb) { rgb[3 * j] = colors[i]; rgb[3 * j + 1] = colors[i + 1]; rgb[3 * j + 2] = colors[i + 2]; }
      }
    }
    this.drawn = { count, total, stride };
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(xyz, 3));
    if (rgb) g.setAttribute('color', new THREE.BufferAttribute(rgb, 3, true));
    const m = new THREE.PointsMaterial({
      size: this.pointSize, sizeAttenuation: false, vertexColors: !!colors, color: colors ? 0xffffff : 0xff7043,
    });
    this.points = new THREE.Points(g, m);
    this.points.name = 'recon';
    this.world.add(this.points);
  }

  /**
   * Shows the completeness samples coloured by label (0 covered: green, 1 missed: red,
   * 2 unseen: grey); at most `max` of them, evenly strided. `null` removes them.
   */
  setCoverage(points, labels, max = 400000) {
    if (this.coverage) { this.world.remove(this.coverage); this.coverage.geometry.dispose(); this.coverage = null; }
    if (!points || !labels || !labels.length) return;
    const step = Math.max(1, Math.ceil(labels.length / max));
    const n = Math.ceil(labels.length / step);
    const pos = new Float32Array(3 * n);
    const col = new Uint8Array(3 * n);
    const palette = [[67, 160, 71], [229, 57, 53], [120, 126, 134]];
    for (let i = 0, k = 0; i < labels.length; i += step, k++) {
      pos.set(points.subarray(3 * i, 3 * i + 3), 3 * k);
      col.set(palette[labels[i]] ?? palette[2], 3 * k);
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    g.setAttribute('color', new THREE.BufferAttribute(col, 3, true));
    this.coverage = new THREE.Points(g, new THREE.PointsMaterial({ size: Math.max(1, this.pointSize - 1), sizeAttenuation: false, vertexColors: true }));
    this.coverage.name = 'coverage';
    this.world.add(this.coverage);
  }

  /**
   * Draws camera frusta (`kind`: 'gtCams' or 'estCams'): `poses` in the ground-truth frame, 14
   * numbers per camera (centre, world_from_cam row-major, tan of the half field of view in x
   * and y; 0 means unknown), each frustum in its `colors` entry (r,g,b bytes) or in `color`.
   * `null` poses remove them. One LineSegments object per kind; `userData.cameras` is the count.
   */
  setCameras(kind, poses, colors = null, color = 0xffffff) {
    this.cams = this.cams || {};
    const old = this.cams[kind];
    if (old) { this.world.remove(old); old.geometry.dispose(); delete this.cams[kind]; }
    if (!poses || !poses.length) return;
    const n = poses.length / 14;
    const depth = 0.1 * this.diag;
    const pos = new Float32Array(n * 16 * 3);
    const col = new Float32Array(n * 16 * 3);
    const base = new THREE.Color(color);
    for (let i = 0; i < n; i++) {
      const p = poses.subarray(14 * i, 14 * i + 14);
      const tx = p[12] > 0 ? p[12] : 0.5;
      const ty = p[13] > 0 ? p[13] : 0.375;
      // a corner (sx, sy) of the image plane at `depth`: centre + R (sx tx, sy ty, 1) depth
      const corner = (sx, sy) => [0, 1, 2].map((r) => p[r] + depth * (p[3 + 3 * r] * sx * tx + p[4 + 3 * r] * sy * ty + p[5 + 3 * r]));
      const c = [p[0], p[1], p[2]];
      const k = [corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1)];
      const segs = [c, k[0], c, k[1], c, k[2], c, k[3], k[0], k[1], k[1], k[2], k[2], k[3], k[3], k[0]];
      const rgb = colors ? [colors[3 * i] / 255, colors[3 * i + 1] / 255, colors[3 * i + 2] / 255] : [base.r, base.g, base.b];
      segs.forEach((v, j) => { pos.set(v, 3 * (16 * i + j)); col.set(rgb, 3 * (16 * i + j)); });
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    g.setAttribute('color', new THREE.BufferAttribute(col, 3));
    const lines = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ vertexColors: true }));
    lines.name = kind;
    lines.userData.cameras = n;
    lines.userData.colors = colors ? Array.from(colors) : null;
    this.cams[kind] = lines;
    lines.visible = this.camVisible ? this.camVisible[kind] !== false : true;
    this.world.add(lines);
  }

  /** Frames the ground truth and every camera drawn (the frusta stand well outside the object). */
  fitCameras() {
    this.fit();
    let r = this.diag / 2;
    for (const o of Object.values(this.cams || {})) {
      const p = o.geometry.attributes.position.array;
      for (let i = 0; i < p.length; i += 3) r = Math.max(r, Math.hypot(p[i] - this.offset[0], p[i + 1] - this.offset[1], p[i + 2] - this.offset[2]));
    }
    const k = (2 * r) / this.diag;
    this.camera.position.multiplyScalar(k);
    this.camera.far = Math.max(this.camera.far, this.diag * 100 * k);
    this.camera.updateProjectionMatrix();
    this.orbit.update();
  }

  /** Cameras drawn per kind: `{gtCams: n, estCams: n}` (hidden ones too). */
  cameraCounts() {
    const out = {};
    for (const [k, o] of Object.entries(this.cams || {})) out[k] = { count: o.userData.cameras, visible: o.visible, colors: o.userData.colors };
    return out;
  }

  setPointSize(s) {
    this.pointSize = s;
    if (this.points) this.points.material.size = s;
    if (this.coverage) this.coverage.material.size = Math.max(1, s - 1);
    if (this.gtMesh && this.gtMesh.isPoints) this.gtMesh.material.size = s;
  }

  setVisible(name, v) {
    if (name === 'gtCams' || name === 'estCams') {
      this.camVisible = { ...(this.camVisible || {}), [name]: v };
      if (this.cams && this.cams[name]) this.cams[name].visible = v;
      return;
    }
    const o = name === 'gt' ? this.gtMesh : name === 'coverage' ? this.coverage : this.points;
    if (o) o.visible = v;
  }

  /** Shows a crop volume: kind 'box' | 'sphere' | 'none'. */
  setCropKind(kind) {
    if (this.cropObject) { this.gizmo.detach(); this.world.remove(this.cropObject); this.cropObject = null; }
    if (kind === 'none') return;
    const geo = kind === 'box' ? new THREE.BoxGeometry(2, 2, 2) : new THREE.SphereGeometry(1, 32, 16);
    const mesh = new THREE.Mesh(geo, new THREE.MeshBasicMaterial({ color: 0x4fc3f7, transparent: true, opacity: 0.12, depthWrite: false }));
    mesh.add(new THREE.LineSegments(new THREE.EdgesGeometry(kind === 'box' ? geo : new THREE.IcosahedronGeometry(1, 1)),
      new THREE.LineBasicMaterial({ color: 0x4fc3f7 })));
    mesh.userData.kind = kind;
    const c = this.offset ?? [0, 0, 0];
    mesh.position.set(c[0], c[1], c[2]);
    const r = this.diag * 0.35;
    mesh.scale.set(r, r, r);
    this.cropObject = mesh;
    this.world.add(mesh);
    this.gizmo.attach(mesh);
  }

  setGizmoMode(mode) {
    this.gizmo.setMode(mode);
  }

  /** The crop volume as a `sfmeval.crop/1` volume, or undefined. */
  cropVolume() {
    const o = this.cropObject;
    if (!o) return undefined;
    if (o.userData.kind === 'polygon_prism') return o.userData.volume;
    const p = o.position;
    if (o.userData.kind === 'sphere') {
      const s = Math.max(o.scale.x, o.scale.y, o.scale.z);
      o.scale.set(s, s, s);
      return { kind: 'sphere', center: [p.x, p.y, p.z], radius: s };
    }
    const m = new THREE.Matrix4().makeRotationFromQuaternion(o.quaternion.clone().normalize());
    const e = m.elements; // column-major
    const rotation = [[e[0], e[4], e[8]], [e[1], e[5], e[9]], [e[2], e[6], e[10]]];
    return {
      kind: 'oriented_box', center: [p.x, p.y, p.z],
      half_extents: [Math.abs(o.scale.x), Math.abs(o.scale.y), Math.abs(o.scale.z)], rotation,
    };
  }

  /**
   * Shows an imported `polygon_prism` volume (Open3D's SelectionPolygonVolume, the Tanks and
   * Temples crop) as the polygon extruded along its axis; it is kept as read (no gizmo).
   */
  setPolygonPrism(v) {
    this.setCropKind('none');
    const [u, w, a] = { x: [1, 2, 0], y: [0, 2, 1], z: [0, 1, 2] }[v.axis];
    const shape = new THREE.Shape(v.polygon.map((p) => new THREE.Vector2(p[u], p[w])));
    const geo = new THREE.ExtrudeGeometry(shape, { depth: v.axis_max - v.axis_min, bevelEnabled: false });
    const basis = (k) => new THREE.Vector3(...[0, 1, 2].map((i) => (i === k ? 1 : 0)));
    const m = new THREE.Matrix4().makeBasis(basis(u), basis(w), basis(a));
    m.setPosition(basis(a).multiplyScalar(v.axis_min));
    geo.applyMatrix4(m);
    const mesh = new THREE.Mesh(geo, new THREE.MeshBasicMaterial({ color: 0x4fc3f7, transparent: true, opacity: 0.12, depthWrite: false, side: THREE.DoubleSide }));
    mesh.add(new THREE.LineSegments(new THREE.EdgesGeometry(geo), new THREE.LineBasicMaterial({ color: 0x4fc3f7 })));
    mesh.userData.kind = 'polygon_prism';
    mesh.userData.volume = v;
    this.cropObject = mesh;
    this.world.add(mesh);
  }

  /** Places the gizmo at a crop volume (from an imported crop file). */
  setCropVolume(v) {
    if (!v) { this.setCropKind('none'); return 'none'; }
    if (v.kind === 'polygon_prism') { this.setPolygonPrism(v); return 'polygon_prism'; }
    const kind = v.kind === 'sphere' ? 'sphere' : 'box';
    this.setCropKind(kind);
    const o = this.cropObject;
    if (v.kind === 'sphere') {
      o.position.set(...v.center);
      o.scale.set(v.radius, v.radius, v.radius);
    } else if (v.kind === 'box') {
      o.position.set(...[0, 1, 2].map((k) => (v.min[k] + v.max[k]) / 2));
      o.scale.set(...[0, 1, 2].map((k) => (v.max[k] - v.min[k]) / 2));
    } else {
      o.position.set(...v.center);
      o.scale.set(...v.half_extents);
      const r = v.rotation;
      const m = new THREE.Matrix4().set(r[0][0], r[0][1], r[0][2], 0, r[1][0], r[1][1], r[1][2], 0, r[2][0], r[2][1], r[2][2], 0, 0, 0, 0, 1);
      o.quaternion.setFromRotationMatrix(m);
    }
    return kind;
  }

  /** Sizes the crop volume to the GT bounds. */
  fitCrop(bounds) {
    const o = this.cropObject;
    if (!o || o.userData.kind === 'polygon_prism') return;
    o.quaternion.identity();
    o.position.set(...[0, 1, 2].map((k) => (bounds[k] + bounds[k + 3]) / 2));
    if (o.userData.kind === 'sphere') {
      const r = this.diag / 2;
      o.scale.set(r, r, r);
    } else {
      o.scale.set(...[0, 1, 2].map((k) => Math.max((bounds[k + 3] - bounds[k]) / 2 * 1.05, this.diag * 1e-3)));
    }
  }

  /** Marks picked pair points (GT frame positions). */
  setMarkers(list) {
    this.pairMarkers.clear();
    const geo = new THREE.SphereGeometry(this.diag * 0.006, 12, 8);
    for (const { p, color } of list) {
      const m = new THREE.Mesh(geo, new THREE.MeshBasicMaterial({ color }));
      m.position.set(p[0], p[1], p[2]);
      this.pairMarkers.add(m);
    }
  }

  pick(e) {
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((e.clientX - rect.left) / rect.width) * 2 - 1, -((e.clientY - rect.top) / rect.height) * 2 + 1);
    this.raycaster.setFromCamera(ndc, this.camera);
    this.raycaster.params.Points.threshold = this.diag * 0.004;
    const targets = [this.gtMesh, this.points].filter((o) => o && o.visible);
    const hits = this.raycaster.intersectObjects(targets, false);
    if (!hits.length) return;
    const h = hits[0];
    const c = this.offset ?? [0, 0, 0];
    if (h.object === this.points) this.onPick({ kind: 'recon', index: h.index * this.drawn.stride });
    else this.onPick({ kind: 'gt', point: [h.point.x + c[0], h.point.y + c[1], h.point.z + c[2]] });
  }

  /** Draws the scene in the next animation frame (once, however many changes come first). */
  requestRender() {
    if (this.renderQueued) return;
    this.renderQueued = true;
    requestAnimationFrame(() => {
      this.renderQueued = false;
      this.renderer.render(this.scene, this.camera);
    });
  }

  screenshot() {
    // drawn now: a change made just before must be in the picture
    this.renderer.render(this.scene, this.camera);
    return this.renderer.domElement.toDataURL('image/png');
  }
}
