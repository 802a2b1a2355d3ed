// The proxy and its body as the page holds them, and the runtime's arithmetic on them: the
// global, local and morph blends and the skin as spx_runtime.h does them (same weights policy, same
// layouts), the body blended or skinned the way the host deforms its mesh, and the paper's
// error: each vertex's distance to the sphere-union surface.

function bytes(b64) {
  const s = atob(b64);
  const out = new Uint8Array(s.length);
  for (let i = 0; i < s.length; ++i) out[i] = s.charCodeAt(i);
  return out.buffer;
}
const f32 = (b64) => new Float32Array(bytes(b64));
const u32 = (b64) => new Uint32Array(bytes(b64));

// The page's data (proxy-export writes it as JSON, arrays as base64 little-endian) decoded.
export function decode(data) {
  const n = data.spheres.count;
  const m = {
    name: data.name,
    up: data.up,
    n,
    poseNames: data.spheres.poses,
    poses: data.spheres.poses.length,
    spheres: f32(data.spheres.xyzr), // pose-major, x y z r per sphere
    sites: f32(data.sites.xyz),
    sphereSite: u32(data.sites.sphere_site),
    skin: null,
    body: null,
    clips: [],
    morph: Boolean(data.morph), // the examples are morph targets: played by blend_morph
  };
  m.siteCount = m.sites.length / 3;
  if (data.skin) {
    m.skin = {
      joints: data.skin.joints,
      xyzr: f32(data.skin.xyzr),
      weights: f32(data.skin.weights),
      indices: u32(data.skin.indices),
      assetJoint: data.skin.asset_joint, // the proxy's joint j is the clips' joint assetJoint[j]
    };
  }
  if (data.body) {
    const b = data.body;
    m.body = {
      triangles: u32(b.triangles),
      vertexCount: b.vertex_count,
      diagonal: b.diagonal,
      size: b.size,
      poses: b.poses ? b.poses.map(f32) : null, // blended: one position array per pose
      vertexSite: b.vertex_site ? u32(b.vertex_site) : null,
      rest: b.rest ? f32(b.rest) : null, // skinned: the rest, the stored positions and their joints
      stored: b.stored ? f32(b.stored) : null,
      influences: b.influences || 0,
      vertexJoints: b.joints ? u32(b.joints) : null,
      vertexWeights: b.weights ? f32(b.weights) : null,
    };
  }
  for (const c of data.clips || [])
    m.clips.push({ name: c.name, frames: c.frames, seconds: c.seconds, joints: c.joints, matrices: f32(c.matrices) });
  return m;
}

// The runtime's weights policy: negatives count as 0, the rest divided by their sum, which must
// be positive; null otherwise (the runtime's SPX_ERR_BAD_WEIGHTS).
export function normalize(w) {
  let sum = 0;
  for (const x of w) {
    if (!Number.isFinite(x)) return null;
    sum += x > 0 ? x : 0;
  }
  if (!(sum > 0)) return null;
  return Float32Array.from(w, (x) => (x > 0 ? x : 0) / sum);
}

// The blend at full weights `w` (one per pose, the rest's first), radii below 0 made 0.
function blendFull(m, w, out) {
  const k = m.n * 4;
  out.fill(0);
  for (let i = 0; i < m.poses; ++i) {
    if (w[i] === 0 && i > 0) continue;
    const s = m.spheres.subarray(i * k, (i + 1) * k);
    for (let j = 0; j < k; ++j) out[j] += w[i] * s[j];
  }
  for (let j = 3; j < k; j += 4) out[j] = out[j] > 0 ? out[j] : 0;
}

// blend_global_xyzr: one weight per pose.
export function blendGlobal(m, weights, out) {
  const w = normalize(weights);
  if (!w) return false;
  blendFull(m, w, out);
  return true;
}

// Morph weights (one per example after the rest) as full weights, the rest's 1 less their sum;
// null where blend_morph refuses them (a weight not finite, magnitudes adding up to 2^24).
export function morphToFull(morph) {
  let sum = 0, magnitude = 0;
  for (const x of morph) {
    if (!Number.isFinite(x)) return null;
    sum += x;
    magnitude += Math.abs(x);
  }
  if (!(magnitude < 16777216)) return null;
  return Float32Array.from([1 - sum, ...morph]);
}

// blend_morph_xyzr: the examples' differences from the rest added at the morph weights.
export function blendMorph(m, morph, out) {
  const w = morphToFull(morph);
  if (!w) return false;
  blendFull(m, w, out);
  return true;
}

// blend_local_normalized: `siteWeights` already normalised, pose count per site (site-major).
export function blendLocal(m, siteWeights, out) {
  const p = m.poses, k = m.n * 4;
  for (let j = 0; j < m.n; ++j) {
    const w = m.sphereSite[j] * p;
    let x = 0, y = 0, z = 0, r = 0;
    for (let i = 0; i < p; ++i) {
      const q = i * k + 4 * j, a = siteWeights[w + i];
      x += a * m.spheres[q];
      y += a * m.spheres[q + 1];
      z += a * m.spheres[q + 2];
      r += a * m.spheres[q + 3];
    }
    out[4 * j] = x;
    out[4 * j + 1] = y;
    out[4 * j + 2] = z;
    out[4 * j + 3] = r > 0 ? r : 0;
  }
}

// The skin's joint matrices (column-major 4x4, the proxy's joint order) of clip `c` at `frame`.
export function proxyMatrices(m, clip, frame) {
  const J = m.skin.joints.length, all = clip.matrices.subarray(frame * clip.joints * 16, (frame + 1) * clip.joints * 16);
  const out = new Float32Array(J * 16);
  for (let j = 0; j < J; ++j) out.set(all.subarray(m.skin.assetJoint[j] * 16, m.skin.assetJoint[j] * 16 + 16), j * 16);
  return out;
}

// out[at..at+2] += w times the column-major matrix at M[a] applied to (x, y, z, 1).
function addSkinned(M, a, w, x, y, z, out, at) {
  out[at] += w * (M[a] * x + M[a + 4] * y + M[a + 8] * z + M[a + 12]);
  out[at + 1] += w * (M[a + 1] * x + M[a + 5] * y + M[a + 9] * z + M[a + 13]);
  out[at + 2] += w * (M[a + 2] * x + M[a + 6] * y + M[a + 10] * z + M[a + 14]);
}

// spx::skin: each centre by linear blend skinning with its 4 joints; the radius as stored.
export function skinSpheres(m, matrices, out) {
  const s = m.skin;
  for (let i = 0; i < m.n; ++i) {
    const cx = s.xyzr[4 * i], cy = s.xyzr[4 * i + 1], cz = s.xyzr[4 * i + 2];
    out.fill(0, 4 * i, 4 * i + 3);
    for (let k = 0; k < 4; ++k)
      addSkinned(matrices, s.indices[4 * i + k] * 16, s.weights[4 * i + k], cx, cy, cz, out, 4 * i);
    out[4 * i + 3] = s.xyzr[4 * i + 3];
  }
}

// The body as the host deforms it: examples blended by the normalised pose weights, each vertex
// by its nearest site's weights in the local blend (as the crash host does).
export function blendBody(body, weights, out) {
  out.fill(0);
  weights.forEach((w, i) => {
    if (w === 0) return;
    const x = body.poses[i];
    for (let v = 0; v < out.length; ++v) out[v] += w * x[v];
  });
}
export function blendBodyLocal(body, poses, siteWeights, out) {
  for (let v = 0; v < body.vertexCount; ++v) {
    const w = body.vertexSite[v] * poses;
    for (let c = 0; c < 3; ++c) {
      let x = 0;
      for (let i = 0; i < poses; ++i) x += siteWeights[w + i] * body.poses[i][3 * v + c];
      out[3 * v + c] = x;
    }
  }
}

// The skinned body: the clip's joint matrices (all of the asset's) on each vertex's stored
// position by its joints; a vertex no joint weighs stays where it is stored.
export function skinBody(body, clip, frame, out) {
  const K = body.influences, M = clip.matrices, base = frame * clip.joints * 16, r = body.stored;
  for (let v = 0; v < body.vertexCount; ++v) {
    const cx = r[3 * v], cy = r[3 * v + 1], cz = r[3 * v + 2];
    if (body.vertexWeights[K * v] === 0) {  // heaviest first: no joint at all
      out.set(r.subarray(3 * v, 3 * v + 3), 3 * v);
      continue;
    }
    out.fill(0, 3 * v, 3 * v + 3);
    for (let k = 0; k < K; ++k) {
      const w = body.vertexWeights[K * v + k];
      if (w !== 0) addSkinned(M, base + body.vertexJoints[K * v + k] * 16, w, cx, cy, cz, out, 3 * v);
    }
  }
}

// Signed distance of each vertex to the union's surface: positive outside every sphere (the gap
// the paper measures), negative inside one (the union pokes out of the body there). Spheres of
// radius 0 are absent. `inside[j]` counts the vertices sphere j holds deeper than `slack` (float
// rounding at a vertex the sphere touches).
export function unionDistance(positions, xyzr, out, inside, slack) {
  const n = xyzr.length / 4;
  inside.fill(0);
  for (let v = 0; v < out.length; ++v) {
    const x = positions[3 * v], y = positions[3 * v + 1], z = positions[3 * v + 2];
    let best = Infinity, holder = -1;
    for (let j = 0; j < n; ++j) {
      const r = xyzr[4 * j + 3];
      if (!(r > 0)) continue;
      const dx = x - xyzr[4 * j], dy = y - xyzr[4 * j + 1], dz = z - xyzr[4 * j + 2];
      const d = Math.sqrt(dx * dx + dy * dy + dz * dz) - r;
      if (d < best) (best = d), (holder = j);
    }
    out[v] = best;
    if (best < -slack) inside[holder] += 1;
  }
}

// Median and max of |distance| and the deepest poke, in % of the diagonal; the spheres that
// hold a vertex.
export function errorStats(dist, inside, diagonal) {
  const a = Float64Array.from(dist, Math.abs).sort();
  let over = 0;
  for (const d of dist) over = Math.max(over, -d);
  let out = 0;
  for (let j = 0; j < inside.length; ++j) if (inside[j] > 0) ++out;
  const pct = (x) => (100 * x) / diagonal;
  return {
    median: a.length ? pct(a.length % 2 ? a[a.length >> 1] : 0.5 * (a[a.length / 2 - 1] + a[a.length / 2])) : 0,
    max: a.length ? pct(a[a.length - 1]) : 0,
    overshoot: pct(over),
    spheresOut: out,
  };
}

export function zeroRadius(xyzr) {
  let z = 0;
  for (let j = 3; j < xyzr.length; j += 4) if (!(xyzr[j] > 0)) ++z;
  return z;
}
