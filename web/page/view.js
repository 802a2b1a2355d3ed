// The scene: the body (semi-transparent, coloured by its error), the spheres (one instanced
// mesh; radius 0 drawn at scale 0), a ground grid under the body, an orbit camera.
import {
  AmbientLight, BufferAttribute, BufferGeometry, Color, DirectionalLight, DoubleSide, GridHelper, IcosahedronGeometry,
  InstancedMesh, Matrix4, Mesh, MeshStandardMaterial, PerspectiveCamera, Raycaster, Scene, Vector2, Vector3,
  WebGLRenderer,
} from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const SPHERE = new Color(0x2f9e8f), POKING = new Color(0x3050ff);
const FOV = 40; // vertical, degrees

// The panel's width on the left (330 px), where the window leaves room for it.
const panelWidth = (w) => (w > 700 ? 330 : 0);

// How far along `side` (a unit vector) from the box's centre the camera must stand for every
// corner of the box to fall in the part of a w x h view the panel leaves free, with a margin. A
// corner v (from the centre) lies at depth d - v.side, and is in view while its offsets across
// the view stay under that depth times the half-angles' tangents.
export function fitDistance(bounds, side, up, w, h) {
  const tanV = 0.9 * Math.tan((FOV * Math.PI) / 360), tanH = (tanV * Math.max(w - panelWidth(w), 1)) / Math.max(h, 1);
  const forward = side.clone().negate(), right = forward.clone().cross(up).normalize();
  const across = right.clone().cross(forward);
  const centre = bounds.min.clone().add(bounds.max).multiplyScalar(0.5);
  let d = 0;
  for (const corner of boxCorners(bounds)) {
    const v = corner.sub(centre);
    d = Math.max(d, v.dot(side) + Math.abs(v.dot(right)) / tanH, v.dot(side) + Math.abs(v.dot(across)) / tanV);
  }
  return d;
}

// The 8 corners of a Box3.
export function boxCorners(box) {
  const corners = [];
  for (let k = 0; k < 8; ++k)
    corners.push(new Vector3((k & 1 ? box.max : box.min).x, (k & 2 ? box.max : box.min).y, (k & 4 ? box.max : box.min).z));
  return corners;
}

// White (on the union) to red (`scale` away); blue where the union pokes out.
export function errorColor(d, scale, out, i) {
  if (d < 0) {
    const t = 0.5 + 0.5 * Math.min(-d / scale, 1);
    out[3 * i] = 1 - t, out[3 * i + 1] = 1 - 0.7 * t, out[3 * i + 2] = 1;
  } else {
    const t = Math.min(d / scale, 1);
    out[3 * i] = 1, out[3 * i + 1] = 1 - t, out[3 * i + 2] = 1 - t;
  }
}

export class View {
  constructor(canvasParent, model, bounds) {
    this.renderer = new WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio);
    canvasParent.appendChild(this.renderer.domElement);
    this.scene = new Scene();
    this.scene.background = new Color(0x20242b);
    this.scene.add(new AmbientLight(0xffffff, 0.9));
    const sun = new DirectionalLight(0xffffff, 1.6);
    this.scene.add(sun);
    const up = model.up === 'z' ? new Vector3(0, 0, 1) : new Vector3(0, 1, 0);
    const centre = bounds.min.clone().add(bounds.max).multiplyScalar(0.5);
    const diag = bounds.max.distanceTo(bounds.min) || 1;
    this.camera = new PerspectiveCamera(FOV, 1, diag / 1000, diag * 100);
    this.camera.up.copy(up);
    const side = (model.up === 'z' ? new Vector3(1.1, -1.4, 0.7) : new Vector3(1.1, 0.7, 1.4)).normalize();
    this.camera.position.copy(centre).addScaledVector(side, fitDistance(bounds, side, up, window.innerWidth, window.innerHeight));
    sun.position.copy(this.camera.position).addScaledVector(up, diag);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.target.copy(centre);
    this.controls.update();
    this.controls.addEventListener('change', () => this.draw());
    this.addGrid(bounds, up, diag);
    this.addSpheres(model.n);
    this.body = null;
    this.raycaster = new Raycaster();
    window.addEventListener('resize', () => this.resize());
    this.resize();
  }

  // A grid on the ground plane under the body, cells of a round length.
  addGrid(bounds, up, diag) {
    const step = 10 ** Math.floor(Math.log10(diag / 4));
    const cells = 2 * Math.ceil((1.2 * diag) / step / 2);
    const grid = new GridHelper(cells * step, cells, 0x8a8f99, 0x3c424d);
    const centre = bounds.min.clone().add(bounds.max).multiplyScalar(0.5);
    if (up.z === 1) grid.rotation.x = Math.PI / 2;
    grid.position.copy(centre);
    if (up.z === 1) grid.position.z = bounds.min.z;
    else grid.position.y = bounds.min.y;
    this.gridStep = step;
    this.scene.add(grid);
  }

  addSpheres(n) {
    const geometry = new IcosahedronGeometry(1, 3);
    const material = new MeshStandardMaterial({ color: 0xffffff, roughness: 0.55, metalness: 0.05 });
    this.spheres = new InstancedMesh(geometry, material, Math.max(n, 1));
    this.spheres.count = n;
    for (let j = 0; j < n; ++j) this.spheres.setColorAt(j, SPHERE);
    this.scene.add(this.spheres);
    this.matrix = new Matrix4();
  }

  addBody(triangles, vertexCount) {
    const g = new BufferGeometry();
    g.setIndex(new BufferAttribute(triangles, 1));
    g.setAttribute('position', new BufferAttribute(new Float32Array(3 * vertexCount), 3));
    g.setAttribute('color', new BufferAttribute(new Float32Array(3 * vertexCount), 3));
    const material = new MeshStandardMaterial({
      vertexColors: true, transparent: true, opacity: 0.55, depthWrite: false, side: DoubleSide, roughness: 0.8,
    });
    this.body = new Mesh(g, material);
    this.body.renderOrder = 1;  // after the spheres, so they show through
    this.scene.add(this.body);
  }

  // The body's positions and per-vertex colours for this frame.
  setBody(positions, colors) {
    const g = this.body.geometry;
    g.attributes.position.array.set(positions);
    g.attributes.position.needsUpdate = true;
    g.attributes.color.array.set(colors);
    g.attributes.color.needsUpdate = true;
    g.computeVertexNormals();
    g.computeBoundingSphere();
    g.computeBoundingBox();
  }

  // Spheres at x y z r; those holding a body vertex (`inside`) in blue.
  setSpheres(xyzr, inside) {
    for (let j = 0; j < this.spheres.count; ++j) {
      const r = xyzr[4 * j + 3];
      this.matrix.makeScale(r, r, r).setPosition(xyzr[4 * j], xyzr[4 * j + 1], xyzr[4 * j + 2]);
      this.spheres.setMatrixAt(j, this.matrix);
      this.spheres.setColorAt(j, inside && inside[j] > 0 ? POKING : SPHERE);
    }
    this.spheres.instanceMatrix.needsUpdate = true;
    this.spheres.instanceColor.needsUpdate = true;
    this.spheres.computeBoundingSphere();
  }

  // Where a point of the scene shows on the page (client pixels).
  toClient(point) {
    const rect = this.renderer.domElement.getBoundingClientRect();
    const p = new Vector3(...point).project(this.camera);
    return [rect.left + ((p.x + 1) / 2) * rect.width, rect.top + ((1 - p.y) / 2) * rect.height];
  }

  // The body's triangle under a canvas point: its vertices and barycentric weights, or null.
  pick(clientX, clientY) {
    if (!this.body) return null;
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
    this.raycaster.setFromCamera(ndc, this.camera);
    const hit = this.raycaster.intersectObject(this.body, false)[0];
    if (!hit || !hit.face) return null;
    return { face: [hit.face.a, hit.face.b, hit.face.c], point: hit.point };
  }

  resize() {
    const w = window.innerWidth, h = window.innerHeight;
    this.renderer.setSize(w, h);
    // The body centred in what the panel (330 px on the left) leaves free.
    const panel = panelWidth(w);
    this.camera.setViewOffset(w + panel, h, 0, 0, w, h);
    this.camera.aspect = (w + panel) / h;
    this.camera.updateProjectionMatrix();
    this.draw();
  }

  draw() {
    this.renderer.render(this.scene, this.camera);
  }
}
