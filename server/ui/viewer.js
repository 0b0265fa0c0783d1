// The map viewer: the source (left) and the target (right) side by side in one WebGL canvas,
// one camera for both. Colourings: correspondence (target vertices by their position in the
// target's box; source vertices by the colour of the point of the target they map to, read
// from morph.glb's morph target), checkerboard (the same through a 3D checker), distortion
// (per-face area ratio of the map, log2, blue = shrunk, red = stretched). Anchors are marked on
// both; the morph slider plays morph.glb. Meshes come as binary glTF (no JSON arrays).

import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

export const BACKGROUND = 0xf4f5f7;

/** The first mesh (with its world transform applied) of a parsed glTF. */
function firstMesh(gltf) {
  let found = null;
  gltf.scene.updateMatrixWorld(true);
  gltf.scene.traverse((o) => { if (!found && o.isMesh) found = o; });
  if (!found) throw new Error('no mesh in the glTF');
  const g = found.geometry.clone();
  g.applyMatrix4(found.matrixWorld);
  return g;
}

async function parse(buf) {
  const loader = new GLTFLoader();
  return firstMesh(await loader.parseAsync(buf, ''));
}

/** Absolute morph target positions (glTF stores displacements, three keeps them relative). */
function morphPositions(g) {
  const rel = g.morphAttributes.position?.at(-1);
  if (!rel) return null;
  const base = g.attributes.position.array;
  const d = rel.array;
  const out = new Float32Array(base.length);
  if (g.morphTargetsRelative) for (let i = 0; i < base.length; i++) out[i] = base[i] + d[i];
  else out.set(d);
  return out;
}

function box(arr) {
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < arr.length; i += 3) {
    for (let k = 0; k < 3; k++) {
      const v = arr[i + k];
      if (v < lo[k]) lo[k] = v;
      if (v > hi[k]) hi[k] = v;
    }
  }
  return { lo, hi, size: hi.map((h, k) => Math.max(h - lo[k], 1e-12)) };
}

/** Colour of a point of the target: its place in the target's box, or a 3D checker of it. */
function colourer(b, mode) {
  const cells = 8;
  return (x, y, z, out, o) => {
    const u = (x - b.lo[0]) / b.size[0];
    const v = (y - b.lo[1]) / b.size[1];
    const w = (z - b.lo[2]) / b.size[2];
    let r = 0.15 + 0.85 * u, g = 0.15 + 0.85 * v, bl = 0.15 + 0.85 * w;
    if (mode === 'checker') {
      const m = Math.max(b.size[0], b.size[1], b.size[2]) / cells;
      const odd = (Math.floor((x - b.lo[0]) / m) + Math.floor((y - b.lo[1]) / m) + Math.floor((z - b.lo[2]) / m)) & 1;
      const s = odd ? 1.0 : 0.25;
      r = odd ? 0.95 : 0.2; g = odd ? 0.95 * s : 0.25; bl = odd ? 0.9 : 0.6;
    }
    out[o] = r; out[o + 1] = g; out[o + 2] = bl;
  };
}

function heat(t) {
  // t in [-1, 1]: blue, white, red.
  const a = Math.min(1, Math.abs(t));
  return t < 0 ? [1 - a, 1 - a * 0.7, 1] : [1, 1 - a * 0.8, 1 - a];
}

function triArea(p, a, b, c) {
  const ux = p[3 * b] - p[3 * a], uy = p[3 * b + 1] - p[3 * a + 1], uz = p[3 * b + 2] - p[3 * a + 2];
  const vx = p[3 * c] - p[3 * a], vy = p[3 * c + 1] - p[3 * a + 1], vz = p[3 * c + 2] - p[3 * a + 2];
  const x = uy * vz - uz * vy, y = uz * vx - ux * vz, z = ux * vy - uy * vx;
  return 0.5 * Math.sqrt(x * x + y * y + z * z);
}

export class Viewer {
  constructor(container) {
    this.container = container;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.renderer.setClearColor(BACKGROUND);
    this.renderer.setScissorTest(true);
    container.append(this.renderer.domElement);
    this.camera = new THREE.PerspectiveCamera(35, 1, 0.01, 100);
    this.camera.position.set(0, 0.4, 3.2);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.draw());
    this.scenes = [new THREE.Scene(), new THREE.Scene()];
    for (const s of this.scenes) {
      s.add(new THREE.HemisphereLight(0xffffff, 0x666677, 1.6));
      const d = new THREE.DirectionalLight(0xffffff, 1.4);
      d.position.set(1, 2, 3);
      s.add(d);
    }
    this.anchorGroups = [new THREE.Group(), new THREE.Group()];
    this.scenes.forEach((s, i) => s.add(this.anchorGroups[i]));
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  resize() {
    const w = this.container.clientWidth, h = this.container.clientHeight;
    this.renderer.setSize(w, h);
    this.camera.aspect = (w / 2) / h;
    this.camera.updateProjectionMatrix();
    this.draw();
  }

  draw() {
    const w = this.container.clientWidth, h = this.container.clientHeight;
    this.scenes.forEach((s, i) => {
      this.renderer.setViewport(i * w / 2, 0, w / 2, h);
      this.renderer.setScissor(i * w / 2, 0, w / 2, h);
      this.renderer.render(s, this.camera);
    });
  }

  /**
   * Shows `source` (morph.glb: the source with a morph target placing it on the target) and
   * `target` (the target mesh), both ArrayBuffers of binary glTF; `anchors` are the spec's.
   */
  async load(sourceGlb, targetGlb, spec) {
    this.src = await parse(sourceGlb);
    this.image = morphPositions(this.src);
    if (targetGlb) {
      this.tgt = await parse(targetGlb);
    } else {
      // The right side is the morph target itself (a quad job's last remesh: same faces).
      this.tgt = new THREE.BufferGeometry();
      this.tgt.setIndex(this.src.index);
      this.tgt.setAttribute('position', new THREE.BufferAttribute(this.image.slice(), 3));
    }
    if (!this.src.attributes.normal) this.src.computeVertexNormals();
    if (!this.tgt.attributes.normal) this.tgt.computeVertexNormals();
    this.targetBox = box(this.tgt.attributes.position.array);
    const mat = () => new THREE.MeshLambertMaterial({ vertexColors: true, side: THREE.DoubleSide });
    this.srcMesh = new THREE.Mesh(this.src, mat());
    this.tgtMesh = new THREE.Mesh(this.tgt, mat());
    // Each mesh centred on its own box and scaled to a unit radius.
    [this.srcMesh, this.tgtMesh].forEach((m, i) => {
      m.geometry.computeBoundingSphere();
      const s = m.geometry.boundingSphere;
      m.scale.setScalar(1 / Math.max(s.radius, 1e-12));
      m.position.copy(s.center).multiplyScalar(-m.scale.x);
      this.scenes[i].add(m);
      this.anchorGroups[i].scale.copy(m.scale);
      this.anchorGroups[i].position.copy(m.position);
    });
    this.spec = spec;
    this.colour('corr');
    this.markAnchors(true);
    this.draw();
    return { sourceVertices: this.src.attributes.position.count, targetVertices: this.tgt.attributes.position.count, morph: !!this.image };
  }

  colour(mode) {
    this.mode = mode;
    const paint = colourer(this.targetBox, mode);
    const tp = this.tgt.attributes.position.array;
    const tc = new Float32Array(tp.length);
    for (let i = 0; i < tp.length; i += 3) {
      if (mode === 'distortion') tc.set([0.8, 0.8, 0.82], i);
      else paint(tp[i], tp[i + 1], tp[i + 2], tc, i);
    }
    this.tgt.setAttribute('color', new THREE.BufferAttribute(tc, 3));
    if (mode === 'distortion') this.distortion();
    else {
      if (this.flat) { this.srcMesh.geometry = this.src; this.flat = null; }
      const img = this.image || this.src.attributes.position.array;
      const sc = new Float32Array(img.length);
      for (let i = 0; i < img.length; i += 3) paint(img[i], img[i + 1], img[i + 2], sc, i);
      this.src.setAttribute('color', new THREE.BufferAttribute(sc, 3));
    }
    this.draw();
  }

  /** Per-face log2 area ratio (image / source, normalized by the total ratio) on the source. */
  distortion() {
    if (!this.image) return;
    const p = this.src.attributes.position.array;
    const idx = this.src.index ? this.src.index.array : null;
    const nf = idx ? idx.length / 3 : p.length / 9;
    const ratio = new Float32Array(nf);
    let sa = 0, ia = 0;
    for (let f = 0; f < nf; f++) {
      const [a, b, c] = idx ? [idx[3 * f], idx[3 * f + 1], idx[3 * f + 2]] : [3 * f, 3 * f + 1, 3 * f + 2];
      const s = triArea(p, a, b, c), t = triArea(this.image, a, b, c);
      sa += s; ia += t;
      ratio[f] = s > 0 ? t / s : 1;
    }
    const norm = ia > 0 ? sa / ia : 1;
    // log2 of the normalized ratio, on a scale set by its 95th percentile (at least 0.1, so a
    // near-isometric map stays pale).
    const logs = ratio.map((r) => Math.log2(Math.max(r * norm, 1e-6)));
    const sorted = Float32Array.from(logs, Math.abs).sort();
    this.distortionScale = Math.max(0.1, sorted[Math.floor(0.95 * (sorted.length - 1))] || 0);
    if (!this.flat) this.flat = this.flatten(idx, p);
    const col = new Float32Array(nf * 9);
    for (let f = 0; f < nf; f++) {
      const c = heat(logs[f] / this.distortionScale);
      for (let k = 0; k < 3; k++) col.set(c, 9 * f + 3 * k);
    }
    this.flat.setAttribute('color', new THREE.BufferAttribute(col, 3));
    this.srcMesh.geometry = this.flat;
  }

  /**
   * The source with one vertex per face corner (for per-face colours), without a morph target:
   * the morph is baked into its positions (a morph texture of that size is slow to build).
   */
  flatten(idx, p) {
    const n = idx ? idx.length : p.length / 3;
    const base = new Float32Array(3 * n), image = new Float32Array(3 * n);
    for (let c = 0; c < n; c++) {
      const v = idx ? idx[c] : c;
      for (let k = 0; k < 3; k++) {
        base[3 * c + k] = p[3 * v + k];
        image[3 * c + k] = this.image[3 * v + k];
      }
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(base.slice(), 3));
    g.computeVertexNormals();
    this.flatBase = base;
    this.flatImage = image;
    this.bake(g, this.weight || 0);
    return g;
  }

  bake(g, w) {
    const pos = g.attributes.position;
    const a = pos.array, b = this.flatBase, im = this.flatImage;
    for (let i = 0; i < a.length; i++) a[i] = b[i] + w * (im[i] - b[i]);
    pos.needsUpdate = true;
  }

  /** Morph weight 0 (the source) to 1 (the source placed on the target). */
  morph(w) {
    this.weight = w;
    // The last morph target: the one the colours follow (a quad job's last remesh).
    const inf = this.srcMesh.morphTargetInfluences;
    if (inf && inf.length) inf[inf.length - 1] = w;
    if (this.flat) this.bake(this.flat, w);
    this.markAnchors(this.anchorGroups[0].visible);
    this.draw();
  }

  markAnchors(show) {
    for (const g of this.anchorGroups) { g.clear(); g.visible = show; }
    const rows = Array.isArray(this.spec?.anchors) ? this.spec.anchors : [];
    const w = this.weight || 0;
    const ps = this.src.attributes.position.array;
    const srcPoint = (v) => {
      const b = [ps[3 * v], ps[3 * v + 1], ps[3 * v + 2]];
      if (!this.image || !w) return b;
      return b.map((x, k) => x + w * (this.image[3 * v + k] - x));
    };
    const tgtPoint = (v) => Array.from(this.tgt.attributes.position.array.slice(3 * v, 3 * v + 3));
    const point = (a, side) => {
      const geom = side ? this.tgt : this.src;
      const n = geom.attributes.position.count;
      if (Number.isInteger(a)) return a >= 0 && a < n ? (side ? tgtPoint(a) : srcPoint(a)) : null;
      if (Array.isArray(a) && a.length === 3) return a;
      return null; // a face/bary point: not drawn
    };
    const r = [this.srcMesh, this.tgtMesh].map((m) => 0.018 / m.scale.x);
    rows.forEach((row, i) => {
      const pair = Array.isArray(row) ? [row[0], row.at(-1)] : [row.source, row.target];
      pair.forEach((a, side) => {
        const p = point(a, side);
        if (!p) return;
        const hue = (i * 0.618) % 1;
        const dot = new THREE.Mesh(new THREE.SphereGeometry(r[side], 12, 8),
          new THREE.MeshBasicMaterial({ color: new THREE.Color().setHSL(hue, 0.9, 0.35) }));
        dot.position.set(p[0], p[1], p[2]);
        this.anchorGroups[side].add(dot);
      });
    });
    this.markFeatures(show);
    this.draw();
  }

  /** The spec's feature curves (vertex paths) as lines on both meshes. */
  markFeatures(show) {
    const feats = Array.isArray(this.spec?.features) ? this.spec.features : [];
    const w = this.weight || 0;
    feats.forEach((f, i) => {
      [f.source, f.target].forEach((path, side) => {
        if (!Array.isArray(path)) return;
        const pos = (side ? this.tgt : this.src).attributes.position;
        const pts = [];
        for (const v of path) {
          if (!Number.isInteger(v) || v < 0 || v >= pos.count) return;
          const p = new THREE.Vector3(pos.getX(v), pos.getY(v), pos.getZ(v));
          if (!side && this.image && w) p.lerp(new THREE.Vector3(...this.image.slice(3 * v, 3 * v + 3)), w);
          pts.push(p);
        }
        const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts),
          new THREE.LineBasicMaterial({ color: new THREE.Color().setHSL((i * 0.618 + 0.3) % 1, 0.9, 0.3) }));
        this.anchorGroups[side].add(line);
      });
    });
    for (const g of this.anchorGroups) g.visible = show;
  }

  /** Counts of pixels unlike the background in the left and right halves (for tests). */
  coverage() {
    this.draw();
    const c = this.renderer.domElement;
    const off = document.createElement('canvas');
    off.width = c.width; off.height = c.height;
    const ctx = off.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const d = ctx.getImageData(0, 0, c.width, c.height).data;
    const bg = new THREE.Color(BACKGROUND);
    const [br, bgc, bb] = [bg.r, bg.g, bg.b].map((x) => Math.round(x * 255));
    const counts = [0, 0];
    for (let y = 0; y < c.height; y++) {
      for (let x = 0; x < c.width; x++) {
        const o = 4 * (y * c.width + x);
        if (Math.abs(d[o] - br) + Math.abs(d[o + 1] - bgc) + Math.abs(d[o + 2] - bb) > 24) counts[x < c.width / 2 ? 0 : 1]++;
      }
    }
    return { left: counts[0], right: counts[1], width: c.width, height: c.height };
  }
}
