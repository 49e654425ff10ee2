// GeomipLoader — a three.js loader for .gip packs that yields a BufferGeometry which refines in place as the
// bytes arrive.
//
//   import { GeomipLoader } from './GeomipLoader.js';
//   new GeomipLoader().load(url, (geometry) => scene.add(new THREE.Mesh(geometry, material)),
//                           (progress) => {}, (error) => {});
//
// onLoad(geometry) is called once, as soon as the first level of detail has arrived; from then on the same
// geometry's `position` and `normal` attributes are overwritten with each finer level (needsUpdate set) and
// the geometry dispatches a 'refine' event ({ type: 'refine', bytes, total, level, done }); its
// `userData.geomip` holds the same fields. Vertices: every grid sample of every patch of the model
// ((2^level+1)² per patch, patch by patch, row-major: the geometry-image order of web/geomip.js's decode()),
// positions in the model's units, normals from the pack's normal maps (nearest sample) or, without them,
// three's computeVertexNormals(). Triangles: two per grid quad, split along the quad's shorter diagonal as
// `geomip decode` does by default (the layout's rule at the four corner quads of a patch, where it welds
// patches, and at ties), rebuilt with each level; quads of the hole mask left out;
// seams are shared positions (bit-identical samples), so the surface has no cracks. Options: `model` (index
// in a consistent pack, default 0), `minInterval` (ms between decodes while streaming, default 100). The
// bytes are read by one streamed GET (fetch), up to the size the pack's manifest gives; parse(arrayBuffer)
// decodes bytes already in memory. `done` is true only when every chunk arrived and checked out; a stream
// that ends early (onLoad may already have been called with a coarser level), a corrupt chunk, a model index
// past the pack's models or bytes that are no pack call onError. `userData.geomip.upright` is the rotation
// of the pack's view frame (`geomip convert --up`) as a Matrix4 array: up +y, front +z (three's and glTF's
// convention); positions stay in the model's units, so apply it to the object:
//   mesh.matrix.fromArray(geometry.userData.geomip.upright); mesh.matrixAutoUpdate = false;
import { BufferAttribute, BufferGeometry, Loader } from 'three';
import { createDecoder } from '../geomip.js';

export class GeomipLoader extends Loader {
  constructor(manager) {
    super(manager);
    this.model = 0;
    this.minInterval = 100;
    this.decoderOptions = {};  // passed to createDecoder (coreUrl, wasmBinary)
  }

  load(url, onLoad, onProgress, onError) {
    const resolved = this.manager.resolveURL(this.path + url);
    this.manager.itemStart(resolved);
    this.stream_(resolved, onLoad, onProgress)
        .catch((e) => { if (onError) onError(e); else console.error(e); this.manager.itemError(resolved); })
        .finally(() => this.manager.itemEnd(resolved));
  }

  loadAsync(url, onProgress) {  // resolves with the geometry at the first level of detail
    return new Promise((resolve, reject) => this.load(url, resolve, onProgress, reject));
  }

  /// The geometry of bytes already in memory (an ArrayBuffer or Uint8Array holding a pack or a prefix; a
  /// prefix gives its coarser level, `userData.geomip.done` false and `total` the whole pack's size).
  /// Throws on bytes that are not a pack, a corrupt chunk before the first level, a model index past the
  /// pack's models, and bytes that hold no level of detail yet.
  async parse(bytes) {
    const decoder = await createDecoder(this.decoderOptions);
    try {
      decoder.push(bytes instanceof Uint8Array ? bytes : new Uint8Array(bytes));
      const result = decoder.decode();
      if ((result.status === 'corrupt' || result.status === 'unsupported-version') &&
          !result.models[this.model]?.geometryPasses)
        throw new Error(`GeomipLoader: ${result.message}`);
      if (result.models.length > 0) checkModel(result, this.model);
      const total = decoder.layout()?.fileSize ?? decoder.size;
      const geometry = new BufferGeometry();
      if (!update(geometry, result, this.model, decoder.size, total, result.status === 'ok'))
        throw new Error(`GeomipLoader: these ${decoder.size} bytes hold no level of detail yet`);
      geometry.userData.geomip.status =
          result.status;  // 'truncated' (a prefix) or 'corrupt' (the last good level)
      return geometry;
    } finally {
      decoder.dispose();
    }
  }

  async stream_(url, onLoad, onProgress) {
    const response = await fetch(url, { headers: this.requestHeader, credentials: this.withCredentials ? 'include' : 'same-origin' });
    if (!response.ok) throw new Error(`GeomipLoader: ${url}: HTTP ${response.status}`);
    const decoder = await createDecoder(this.decoderOptions);
    const reader = response.body.getReader();
    try {
      // The pack's size comes from its manifest (Content-Length may be absent or be a server's word); bytes
      // past it are not read.
      let total = 0;
      const geometry = new BufferGeometry();
      let loaded = false, lastDecode = -Infinity;
      const refine = (last) => {
        const now = performance.now();
        if (!last && now - lastDecode < this.minInterval) return;
        lastDecode = now;
        const result = decoder.decode();
        if (result.status === 'corrupt' || result.status === 'unsupported-version')
          throw new Error(`GeomipLoader: ${url}: ${result.message} (after ${result.bytesUsed} bytes)`);
        if (result.models.length > 0) checkModel(result, this.model);
        if (!update(
                geometry, result, this.model, decoder.size, total || decoder.size, result.status === 'ok'))
          return;
        if (!loaded) {
          loaded = true;
          onLoad(geometry);
        }
        geometry.dispatchEvent({type: 'refine', ...geometry.userData.geomip});
      };
      for (;;) {
        const {done, value} = await reader.read();
        if (done) break;
        let bytes = value;
        if (total && decoder.size + bytes.length > total) bytes = bytes.subarray(0, total - decoder.size);
        decoder.push(bytes);
        if (!total) total = decoder.layout()?.fileSize ?? 0;  // throws GeomipError on bytes that are no pack
        if (onProgress) onProgress({loaded: decoder.size, total});
        refine(false);
        if (total && decoder.size >= total) break;
      }
      refine(true);  // the last bytes, always decoded
      const size = decoder.size;
      if (!loaded) throw new Error(`GeomipLoader: ${url}: no level of detail in ${size} bytes`);
      if (!total || size < total)
        throw new Error(
            `GeomipLoader: ${url}: the stream ended at ${size} of ${total || '?'} bytes (the geometry ` +
            `keeps level ${geometry.userData.geomip.level})`);
    } finally {
      reader.cancel().catch(() => {});
      decoder.dispose();
    }
  }
}

/// Throws when `result` (a decode with the manifest in) has no model `m`.
function checkModel(result, m) {
  if (m >= result.models.length)
    throw new Error(
        `GeomipLoader: model ${m} is out of range: the pack has ${result.models.length} model(s)`);
}

/// The rotation of the pack's view frame (the 4×4 row-major normalization of geomip.js's decode(): rotation
/// over extent, then the centring) as a three.js Matrix4 array (column-major); the identity when the pack
/// stores none.
function uprightMatrix(n) {
  const scale = Math.hypot(n[0], n[1], n[2]) || 1;
  const m = new Array(16).fill(0);
  for (let r = 0; r < 3; ++r)
    for (let c = 0; c < 3; ++c) m[c * 4 + r] = n[r * 4 + c] / scale;
  m[15] = 1;
  return m;
}

/// Writes model `m` of a decode() result into `geometry`; false when it has no model yet.
function update(geometry, result, m, bytes, total, done) {
  const model = result.models[m];
  if (!model || model.geometryPasses === 0) return false;
  const size = (1 << model.level) + 1, per = size * size;
  const count = model.numPatches * per;
  let position = geometry.getAttribute('position');
  if (!position || position.count !== count) {
    // A new level: the renderer frees the old buffers (dispose), then uploads the new ones.
    if (position) geometry.dispose();
    position = new BufferAttribute(new Float32Array(count * 3), 3);
    geometry.setAttribute('position', position);
    geometry.setAttribute('normal', new BufferAttribute(new Float32Array(count * 3), 3));
  }
  for (let p = 0; p < model.numPatches; ++p) position.array.set(model.geometry[p], p * per * 3);
  position.needsUpdate = true;

  // triangles: each quad along its shorter diagonal, so rebuilt with every level (the positions changed); the
  // same buffer while the triangle count stays
  const triangles = gridIndex(model, size), index = geometry.getIndex();
  if (index && index.array.length === triangles.length) {
    index.array.set(triangles);
    index.needsUpdate = true;
  } else {
    geometry.setIndex(new BufferAttribute(triangles, 1));
  }

  const normal = geometry.getAttribute('normal');
  if (model.normals.length === model.numPatches) {
    const nsize = (1 << model.normalLevel) + 1;
    for (let p = 0; p < model.numPatches; ++p)
      for (let j = 0; j < size; ++j)
        for (let i = 0; i < size; ++i) {
          const ni = Math.round(i * (nsize - 1) / (size - 1)), nj = Math.round(j * (nsize - 1) / (size - 1));
          const src = (nj * nsize + ni) * 3, dst = (p * per + j * size + i) * 3;
          normal.array[dst] = model.normals[p][src];
          normal.array[dst + 1] = model.normals[p][src + 1];
          normal.array[dst + 2] = model.normals[p][src + 2];
        }
    normal.needsUpdate = true;
  } else {
    geometry.computeVertexNormals();
  }
  geometry.computeBoundingBox();
  geometry.computeBoundingSphere();
  geometry.userData.geomip = {
    bytes,
    total,
    level: model.detailLevel,
    done,
    name: model.name,
    upright: uprightMatrix(model.normalization),
  };
  return true;
}

/// Two triangles per grid quad, patch by patch, leaving out the quads whose hole-mask cell is set (the
/// quad's centre in the mask's grid, as the viewers do).
// Squared distance between samples u and v of one patch's xyz grid.
function dist2(x, u, v) {
  const dx = x[3 * u] - x[3 * v], dy = x[3 * u + 1] - x[3 * v + 1], dz = x[3 * u + 2] - x[3 * v + 2];
  return dx * dx + dy * dy + dz * dz;
}

function gridIndex(model, size) {
  const res = model.holeMaskLevel >= 0 ? 1 << model.holeMaskLevel : 0;
  const per = size * size;
  const out = [];
  for (let p = 0; p < model.numPatches; ++p)
    for (let j = 0; j + 1 < size; ++j)
      for (let i = 0; i + 1 < size; ++i) {
        if (res) {
          const qi = Math.min(res - 1, Math.floor((i + 0.5) / (size - 1) * res));
          const qj = Math.min(res - 1, Math.floor((j + 0.5) / (size - 1) * res));
          if (model.holeMask[p][qj * res + qi]) continue;
        }
        const a = p * per + j * size + i, b = a + 1, c = a + size + 1, d = a + size;
        const x = model.geometry[p], k = j * size + i;
        // As geomip decode (gimage/uniform_remesh.h): the layout's rule (a–c when i + j + p is even) at the
        // four corner quads of a patch, where two patches' quads can share three vertices, and at ties.
        let ac = (i + j + p) % 2 === 0;
        const corner = (i === 0 || i === size - 2) && (j === 0 || j === size - 2);
        if (!corner) {
          const diff = dist2(x, k, k + size + 1) - dist2(x, k + 1, k + size);
          if (diff < 0) ac = true;
          if (diff > 0) ac = false;
        }
        if (ac)
          out.push(a, b, c, a, c, d);
        else out.push(a, b, d, b, c, d);
      }
  return new Uint32Array(out);
}
