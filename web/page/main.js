// The proxy page: reads the data proxy-export wrote into the page, draws the body and its spheres,
// and plays them: sliders per example and local-blend painting for a blended proxy, a slider per
// morph target for a morph-target body's, a clip list, play/pause and a scrubber for a skinned
// one. The readout and <body data-*> say what is shown.
import { Box3, Triangle, Vector3 } from 'three';
import * as M from './model.js';
import { View, boxCorners, errorColor } from './view.js';

const CSS = `
html,body{margin:0;height:100%;overflow:hidden;background:#20242b;font:13px/1.45 system-ui,sans-serif;color:#e8eaed}
#spx-panel{position:absolute;top:10px;left:10px;width:310px;max-height:calc(100% - 20px);overflow:auto;
  background:rgba(24,27,33,.88);border:1px solid #3a404b;border-radius:6px;padding:10px 12px;box-sizing:border-box}
#spx-panel h1{font-size:15px;margin:0 0 6px}#spx-panel h2{font-size:12px;margin:10px 0 4px;color:#9aa3b2;text-transform:uppercase}
#spx-panel label{display:flex;align-items:center;gap:6px;margin:2px 0}#spx-panel input[type=range]{flex:1;min-width:0}
#spx-panel .w{width:38px;text-align:right;font-variant-numeric:tabular-nums;color:#9aa3b2}
#spx-panel button,#spx-panel select{background:#2c313a;color:#e8eaed;border:1px solid #4a5160;border-radius:4px;padding:2px 8px}
#spx-readout div{font-variant-numeric:tabular-nums}#spx-legend{margin-top:6px}
#spx-legend .bar{height:10px;border-radius:2px;background:linear-gradient(90deg,#fff,#f00)}
#spx-legend .ends{display:flex;justify-content:space-between;color:#9aa3b2}
#spx-legend .poke{display:inline-block;width:10px;height:10px;background:#4d5cff;border-radius:2px;vertical-align:-1px}
#spx-error{color:#ff8a80}`;

function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
}

const pct = (x) => `${x.toFixed(3)} %`;
const short = (x) => Number(x.toPrecision(3)).toString();
// "1 pose", "3 poses": a count and its noun.
const counted = (n, noun) => `${n} ${noun}${n === 1 ? '' : 's'}`;

// A round colour scale above `x` (1, 2 or 5 times a power of ten).
function roundUp(x) {
  const p = 10 ** Math.floor(Math.log10(x));
  for (const m of [1, 2, 5, 10]) if (m * p >= x) return m * p;
  return 10 * p;
}

class Page {
  constructor(data) {
    this.m = M.decode(data);
    const m = this.m;
    this.xyzr = new Float32Array(4 * m.n);
    this.mode = m.skin && m.clips.length && m.body && m.body.rest ? 'clip' : m.morph ? 'morph' : 'blend';
    this.weights = Array.from({ length: m.poses }, (_, i) => (i === 0 ? 1 : 0));
    this.morphWeights = Array.from({ length: m.poses - 1 }, () => 0);
    this.local = false;
    this.siteWeights = null;
    this.clip = 0;
    this.frame = 0;
    this.playing = false;
    if (m.body) {
      this.positions = new Float32Array(3 * m.body.vertexCount);
      this.dist = new Float32Array(m.body.vertexCount);
      this.colors = new Float32Array(3 * m.body.vertexCount);
    }
    this.inside = new Uint32Array(m.n);
    this.view = new View(document.body, m, this.bounds());
    if (m.body) {
      this.view.addBody(m.body.triangles, m.body.vertexCount);
      this.view.renderer.domElement.addEventListener('click', (e) => this.paintAt(e.clientX, e.clientY));
    }
    this.buildPanel();
    this.update();
    if (m.body) {
      this.scale = roundUp(Math.max(this.stats.max, 1e-3));  // fixed, so frames compare
      this.legendEnds.lastChild.textContent = `${this.scale} % of the diagonal`;
      this.update();
    }
  }

  // The box the camera frames: the body at rest, else the rest spheres.
  bounds() {
    const box = new Box3(), v = new Vector3(), m = this.m;
    if (m.body) {
      const x = m.body.rest || m.body.poses[0];
      for (let i = 0; i < x.length; i += 3) box.expandByPoint(v.set(x[i], x[i + 1], x[i + 2]));
    } else {
      for (let j = 0; j < m.n; ++j) {
        const s = m.spheres.subarray(4 * j, 4 * j + 4);
        box.expandByPoint(v.set(s[0] - s[3], s[1] - s[3], s[2] - s[3]));
        box.expandByPoint(v.set(s[0] + s[3], s[1] + s[3], s[2] + s[3]));
      }
    }
    return box;
  }

  // The spheres and the body for what the controls say, as the runtime and the host compute them.
  pose() {
    const m = this.m;
    if (this.mode === 'clip') {
      const c = m.clips[this.clip];
      this.matrices = M.proxyMatrices(m, c, this.frame);
      M.skinSpheres(m, this.matrices, this.xyzr);
      if (m.body) M.skinBody(m.body, c, this.frame, this.positions);
      return true;
    }
    if (this.mode === 'morph') {
      const w = M.morphToFull(this.morphWeights);
      if (!w) return false;
      M.blendMorph(m, this.morphWeights, this.xyzr);
      if (m.body) M.blendBody(m.body, w, this.positions);  // the rest plus each target's move
      return true;
    }
    if (this.local) {
      M.blendLocal(m, this.siteWeights, this.xyzr);
      if (m.body) M.blendBodyLocal(m.body, m.poses, this.siteWeights, this.positions);
      return true;
    }
    const w = M.normalize(this.weights);
    if (!w) return false;
    M.blendGlobal(m, this.weights, this.xyzr);
    if (m.body) M.blendBody(m.body, w, this.positions);
    return true;
  }

  update() {
    const m = this.m;
    this.errorLine.textContent = this.pose() ? '' : 'weights need a positive entry (the runtime rejects them)';
    if (m.body) {
      M.unionDistance(this.positions, this.xyzr, this.dist, this.inside, 1e-6 * m.body.diagonal);
      this.stats = M.errorStats(this.dist, this.inside, m.body.diagonal);
      const scale = ((this.scale || 1) * m.body.diagonal) / 100;
      for (let v = 0; v < this.dist.length; ++v) errorColor(this.dist[v], scale, this.colors, v);
      this.view.setBody(this.positions, this.colors);
    }
    this.view.setSpheres(this.xyzr, m.body ? this.inside : null);
    this.view.draw();
    this.showReadout();
  }

  showReadout() {
    const m = this.m, zero = M.zeroRadius(this.xyzr), b = document.body.dataset, s = this.stats;
    const joints = m.skin ? m.skin.joints.length : 0;
    this.readout.replaceChildren(
      el('div', {}, `${counted(m.n, 'sphere')}${zero ? ` (${zero} of radius 0, hidden)` : ''} · ${counted(m.poses, 'pose')}${joints ? ` · ${counted(joints, 'joint')}` : ''}`),
      el('div', {}, s ? `error median ${pct(s.median)} · max ${pct(s.max)} of the diagonal` : 'no body given: proxy-export --rest/--pose, --manifest or --asset adds it'),
      el('div', {}, s ? `${s.spheresOut === 1 ? '1 sphere pokes' : `${s.spheresOut} spheres poke`} out${s.spheresOut ? ` (deepest ${pct(s.overshoot)})` : ''}` : ''),
      el('div', {}, m.body ? `body ${m.body.size.map(short).join(' × ')} (diagonal ${short(m.body.diagonal)}), grid squares ${short(this.view.gridStep)} wide` : ''),
    );
    Object.assign(b, {
      spheres: m.n, poses: m.poses, joints, zeroRadius: zero,
      maxError: s ? s.max.toPrecision(6) : 'none', medianError: s ? s.median.toPrecision(6) : 'none',
      spheresOut: s ? s.spheresOut : 'none', mode: this.mode, clip: this.clip, frame: this.frame,
    });
    b.spxReady = '1';
  }

  buildPanel() {
    const m = this.m;
    document.head.append(el('style', {}, CSS));
    this.readout = el('div', { id: 'spx-readout' });
    this.errorLine = el('div', { id: 'spx-error' });
    const panel = el('div', { id: 'spx-panel' }, el('h1', {}, m.name), this.readout, this.errorLine);
    if (m.body) {
      this.legendEnds = el('div', { class: 'ends' }, el('span', {}, '0'), el('span', {}, ''));
      panel.append(el('div', { id: 'spx-legend' }, el('div', { class: 'bar' }), this.legendEnds,
        el('div', {}, el('span', { class: 'poke' }), ' the union pokes out (and the spheres that do)')));
    }
    if (this.mode === 'clip') panel.append(...this.clipControls());
    else if (this.mode === 'morph') panel.append(...this.morphControls());
    else if (m.poses > 1) panel.append(...this.blendControls());
    document.body.append(panel);
  }

  blendControls() {
    const m = this.m, out = [el('h2', {}, 'examples (global blend)')];
    this.weightLabels = [];
    this.sliders = this.weights.map((w, i) => {
      const label = el('span', { class: 'w' }, '');
      const input = el('input', { type: 'range', min: 0, max: 1, step: 0.01, value: w, 'data-pose': i,
        oninput: () => { this.weights[i] = Number(input.value); this.local = false; this.syncBlend(); this.update(); } });
      this.weightLabels.push(label);
      out.push(el('label', {}, el('span', { style: 'width:90px;overflow:hidden' }, m.poseNames[i]), input, label));
      return input;
    });
    this.syncBlend();
    if (m.body && m.body.vertexSite) {
      this.paintPose = el('select', { id: 'spx-paint-pose' }, ...m.poseNames.map((n, i) => el('option', { value: i }, n)));
      this.paintPose.value = String(Math.min(1, m.poses - 1));
      this.paintRadius = el('input', { type: 'range', min: 1, max: 50, step: 1, value: 15, id: 'spx-paint-radius' });
      this.paintStrength = el('input', { type: 'range', min: 0.05, max: 1, step: 0.05, value: 0.5, id: 'spx-paint-strength' });
      this.localBox = el('input', { type: 'checkbox', id: 'spx-local',
        onchange: () => { this.setLocal(this.localBox.checked); this.update(); } });
      out.push(el('h2', {}, 'local blend (click the body to dent)'),
        el('label', {}, this.localBox, 'paint weights onto the blend sites'),
        el('label', {}, 'towards', this.paintPose),
        el('label', {}, 'radius (% of diagonal)', this.paintRadius),
        el('label', {}, 'strength', this.paintStrength),
        el('button', { onclick: () => { this.setLocal(true); this.update(); } }, 'reset to the sliders'));
    }
    return out;
  }

  // A morph-target body: one slider per target, added as the host's blend shapes add them.
  morphControls() {
    const m = this.m, out = [el('h2', {}, 'morph targets (spx::blend_morph)')];
    this.morphWeights.forEach((w, i) => {
      const label = el('span', { class: 'w' }, w.toFixed(2));
      const input = el('input', { type: 'range', min: 0, max: 1, step: 0.01, value: w, 'data-pose': i + 1,
        oninput: () => { this.morphWeights[i] = Number(input.value); label.textContent = this.morphWeights[i].toFixed(2); this.update(); } });
      out.push(el('label', {}, el('span', { style: 'width:90px;overflow:hidden' }, m.poseNames[i + 1]), input, label));
    });
    return out;
  }

  syncBlend() {
    const w = M.normalize(this.weights);
    this.weightLabels.forEach((l, i) => (l.textContent = w ? w[i].toFixed(2) : '–'));
    if (this.localBox) this.localBox.checked = this.local;
  }

  // Local mode starts every site at the sliders' (normalised) weights.
  setLocal(on) {
    const m = this.m, w = M.normalize(this.weights) || Float32Array.from(this.weights, (_, i) => (i ? 0 : 1));
    this.local = on;
    this.siteWeights = new Float32Array(m.siteCount * m.poses);
    for (let s = 0; s < m.siteCount; ++s) this.siteWeights.set(w, s * m.poses);
    this.localBox.checked = on;
  }

  // The crash host's dent: sites near the rest point under the click move their weights toward
  // the chosen example, by a falloff (1 - d/R)^2 times the strength; weights stay convex.
  paintAt(x, y) {
    if (this.mode !== 'blend' || !this.localBox) return;
    const hit = this.view.pick(x, y);
    if (!hit) return;
    if (!this.local) this.setLocal(true);
    const m = this.m, rest = m.body.poses[0], cur = this.positions;
    const at = (a, i) => new Vector3(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
    const [a, b, c] = hit.face, bary = new Vector3();
    Triangle.getBarycoord(hit.point, at(cur, a), at(cur, b), at(cur, c), bary);
    const point = at(rest, a).multiplyScalar(bary.x).addScaledVector(at(rest, b), bary.y).addScaledVector(at(rest, c), bary.z);
    this.paint(point.toArray(), Number(this.paintPose.value), (Number(this.paintRadius.value) / 100) * m.body.diagonal,
      Number(this.paintStrength.value));
  }

  paint(point, pose, radius, strength) {
    const m = this.m, p = m.poses;
    for (let s = 0; s < m.siteCount; ++s) {
      const d = Math.hypot(m.sites[3 * s] - point[0], m.sites[3 * s + 1] - point[1], m.sites[3 * s + 2] - point[2]);
      if (d >= radius) continue;
      const a = Math.min(1, strength * (1 - d / radius) ** 2);
      for (let k = 0; k < p; ++k) this.siteWeights[s * p + k] = (1 - a) * this.siteWeights[s * p + k] + (k === pose ? a : 0);
    }
    this.update();
  }

  clipControls() {
    const m = this.m;
    this.clipSelect = el('select', { id: 'spx-clip', onchange: () => this.setClip(Number(this.clipSelect.value)) },
      ...m.clips.map((c, i) => el('option', { value: i }, `${c.name || `clip ${i}`} (${c.seconds.toFixed(2)} s)`)));
    this.playButton = el('button', { id: 'spx-play', onclick: () => this.togglePlay() }, 'play');
    this.scrubber = el('input', { type: 'range', id: 'spx-scrubber', min: 0, max: 0, step: 1, value: 0,
      oninput: () => { this.playing = false; this.playButton.textContent = 'play'; this.setFrame(Number(this.scrubber.value)); } });
    this.timeLabel = el('span', { class: 'w', style: 'width:64px' }, '');
    this.setClip(0, false);
    return [el('h2', {}, 'clip (skinned as the runtime does)'), el('label', {}, this.clipSelect, this.playButton),
      el('label', {}, this.scrubber, this.timeLabel)];
  }

  time(frame) {
    const c = this.m.clips[this.clip];
    return c.frames > 1 ? (c.seconds * frame) / (c.frames - 1) : 0;
  }

  setClip(i, draw = true) {
    this.clip = i;
    this.scrubber.max = this.m.clips[i].frames - 1;
    this.setFrame(0, draw);
  }

  setFrame(f, draw = true) {
    this.frame = f;
    this.scrubber.value = f;
    this.timeLabel.textContent = `${this.time(f).toFixed(2)} s`;
    if (draw) this.update();
  }

  togglePlay() {
    this.playing = !this.playing;
    this.playButton.textContent = this.playing ? 'pause' : 'play';
    if (!this.playing) return;
    const c = this.m.clips[this.clip], start = performance.now() - this.time(this.frame) * 1000;
    const tick = (now) => {
      if (!this.playing) return;
      const t = c.seconds > 0 ? ((now - start) / 1000) % c.seconds : 0;
      const f = c.frames > 1 ? Math.round((t / c.seconds) * (c.frames - 1)) : 0;
      if (f !== this.frame) this.setFrame(f);
      requestAnimationFrame(tick);
    };
    requestAnimationFrame(tick);
  }

  // For scripts (the browser test): what is shown, as the runtime's inputs and outputs.
  state() {
    const s = { mode: this.mode, xyzr: Array.from(this.xyzr), stats: this.stats || null };
    if (this.mode === 'clip') Object.assign(s, { clip: this.clip, frame: this.frame, matrices: Array.from(this.matrices) });
    else if (this.mode === 'morph') s.morphWeights = this.morphWeights.slice();
    else if (this.local) s.siteWeights = Array.from(this.siteWeights);
    else s.weights = this.weights.slice();
    return s;
  }
}

const data = JSON.parse(document.getElementById('spx-data').textContent);
const page = new Page(data);
// For scripts: what is shown, where the body's centre shows on the page (to click it), and
// where its box's corners show.
window.spxPage = {
  state: () => page.state(),
  centreOnPage: () => {
    const b = page.bounds();
    return page.view.toClient(b.min.clone().add(b.max).multiplyScalar(0.5).toArray());
  },
  cornersOnPage: () => boxCorners(page.bounds()).map((c) => page.view.toClient(c.toArray())),
};
