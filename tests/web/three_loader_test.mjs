// web/three/GeomipLoader.js under node against the native decoder: a pack served by a throttled local HTTP
// server (512-byte writes) loads into a three.js BufferGeometry that refines in place — at least 3
// refinements, the first before all bytes are in — and at the first refinement and at the end its vertex
// count and every position equal the native codec::decode_pack grids of the same byte prefix bit for bit
// (pack_prefix_hashes --dump); the index holds two triangles per quad outside the hole mask, all in range.
//   node three_loader_test.mjs NATIVE_TOOL PACK:MODEL...
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import http from 'node:http';
import { GeomipLoader } from '../../web/three/GeomipLoader.js';

const [nativeTool, ...specs] = process.argv.slice(2);
let failures = 0;
const check = (ok, what) => { console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`); if (!ok) ++failures; };

/// Model `m` of the native decode of the first `bytes` bytes: { patches, level, holeLevel, geometry
/// (Uint32Array of the float bits, patch by patch), holes (per patch Uint8Array) }.
function native(pack, bytes, m) {
  const dump = execFileSync(nativeTool, [pack, '--dump', String(bytes)], { maxBuffer: 1 << 28 });
  const w = new Uint32Array(dump.buffer, dump.byteOffset, dump.length / 4);
  let at = 4;
  for (let k = 0; k < w[3]; ++k) {
    const [patches, level, normalLevel, holeLevel] = [w[at], w[at + 1] | 0, w[at + 2] | 0, w[at + 3] | 0];
    at += 6;
    const per = ((1 << level) + 1) ** 2 * 3, nper = normalLevel >= 0 ? ((1 << normalLevel) + 1) ** 2 * 3 : 0;
    const hper = holeLevel >= 0 ? 1 << (2 * holeLevel) : 0;
    const geometry = new Uint32Array(patches * per), holes = [];
    for (let p = 0; p < patches; ++p) {
      geometry.set(w.subarray(at, at + per), p * per);
      at += per + nper;
      holes.push(Uint8Array.from(w.subarray(at, at + hper)));
      at += hper;
    }
    if (k === m) return { patches, level, holeLevel, geometry, holes };
  }
  throw new Error(`no model ${m} at ${bytes} bytes`);
}

function checkAgainstNative(label, pack, bytes, m, positions, index) {
  const n = native(pack, bytes, m);
  const size = (1 << n.level) + 1;
  const bits = new Uint32Array(positions.buffer, positions.byteOffset, positions.length);
  let same = bits.length === n.geometry.length;
  for (let i = 0; same && i < bits.length; ++i) same = bits[i] === n.geometry[i];
  check(same, `${label}: ${positions.length / 3} vertices (native: ${n.patches} × ${size}²), positions bit-identical to native at ${bytes} bytes`);
  const quads = [];  // [p, i, j] of every quad outside the hole mask, in the loader's order
  const res = n.holeLevel >= 0 ? 1 << n.holeLevel : 0;
  for (let p = 0; p < n.patches; ++p)
    for (let j = 0; j + 1 < size; ++j)
      for (let i = 0; i + 1 < size; ++i) {
        const masked = res && n.holes[p][Math.min(res - 1, Math.floor((j + 0.5) / (size - 1) * res)) * res +
                                         Math.min(res - 1, Math.floor((i + 0.5) / (size - 1) * res))];
        if (!masked) quads.push([p, i, j]);
      }
  const inRange = index.every((v) => v < positions.length / 3);
  check(index.length === quads.length * 6 && inRange,
        `${label}: ${index.length / 3} triangles = 2 × ${quads.length} quads outside the hole mask, indices in range`);
  // The split of geomip decode (gimage/uniform_remesh.h): each quad along its shorter diagonal, the layout's
  // rule (a–c when i + j + p is even) at ties and at the four corner quads of a patch, where two patches'
  // quads can share three vertices (without it two triangles are duplicated across the seam: a fin).
  const d2 = (u, v) => {
    let s = 0;
    for (let k = 0; k < 3; ++k) s += (positions[3 * u + k] - positions[3 * v + k]) ** 2;
    return s;
  };
  let wrong = 0, badShape = 0;
  quads.forEach(([p, i, j], q) => {
    const a = p * size * size + j * size + i, b = a + 1, c = a + size + 1, d = a + size;
    const t = index.slice(6 * q, 6 * q + 6);
    const alongAc = t.join() === [a, b, c, a, c, d].join(), alongBd = t.join() === [a, b, d, b, c, d].join();
    if (!alongAc && !alongBd) { ++badShape; return; }
    const corner = (i === 0 || i === size - 2) && (j === 0 || j === size - 2);
    const diff = d2(a, c) - d2(b, d);
    const want = corner || diff === 0 ? (i + j + p) % 2 === 0 : diff < 0;
    if (alongAc !== want) ++wrong;
  });
  check(wrong === 0 && badShape === 0,
        `${label}: every quad split as geomip decode splits it (${wrong} otherwise, ${badShape} not a quad)`);
}

for (const spec of specs) {
  const [pack, modelText] = spec.split(':');
  const model = Number(modelText ?? 0);
  const bytes = readFileSync(pack);
  const server = http.createServer(async (req, res) => {
    res.writeHead(200, { 'Content-Type': 'application/octet-stream', 'Content-Length': bytes.length });
    for (let at = 0; at < bytes.length; at += 512) {
      res.write(bytes.subarray(at, Math.min(bytes.length, at + 512)));
      await new Promise((r) => setTimeout(r, 15));
    }
    res.end();
  });
  await new Promise((r) => server.listen(0, '127.0.0.1', r));
  const url = `http://127.0.0.1:${server.address().port}/pack.gip`;
  const loader = new GeomipLoader();
  loader.model = model;
  loader.minInterval = 0;
  const refinements = [];
  const done = new Promise((resolve, reject) => {
    loader.load(url, (geometry) => {
      const record = (e) => {
        refinements.push({ bytes: e.bytes, positions: geometry.getAttribute('position').array.slice(),
                           index: geometry.getIndex().array.slice() });
        if (e.done) resolve(geometry);
      };
      record({ ...geometry.userData.geomip });
      geometry.addEventListener('refine', (e) => { if (e.bytes !== refinements.at(-1).bytes || e.done) record(e); });
    }, undefined, reject);
  });
  const geometry = await done;
  server.close();
  const label = `${pack} model ${model}`;
  check(refinements.length >= 3 && refinements[0].bytes < bytes.length && refinements.at(-1).bytes === bytes.length,
        `${label}: ${refinements.length} refinements, at ${refinements.slice(0, 4).map((r) => r.bytes).join(', ')}, …, ${refinements.at(-1).bytes} bytes`);
  const first = refinements[0];
  checkAgainstNative(`${label} first level`, pack, first.bytes, model, first.positions, first.index);
  checkAgainstNative(`${label} complete`, pack, bytes.length, model, geometry.getAttribute('position').array,
                     geometry.getIndex().array);
  const normal = geometry.getAttribute('normal').array;
  let unit = 0;
  for (let i = 0; i < normal.length; i += 3) if (Math.abs(Math.hypot(normal[i], normal[i + 1], normal[i + 2]) - 1) < 0.01) ++unit;
  check(unit === normal.length / 3, `${label}: ${unit} of ${normal.length / 3} normals of unit length`);
}
// Streams that end early, corrupt chunks and a model past the pack's: onError, `done` never true; parse()
// of a prefix says what it is. The first pack serves for all.
{
  const [pack] = specs[0].split(':');
  const bytes = readFileSync(pack);
  const flipped = Uint8Array.from(bytes);
  flipped[bytes.length - 10] ^= 0x40;  // in the last chunk: the levels before it stay
  const cases = [
    { name: 'truncated', body: bytes.subarray(0, Math.floor(bytes.length * 0.6)), error: /ended at/ },
    { name: 'corrupt', body: flipped, error: /corrupt/ },
    { name: 'model 9', body: bytes, model: 9, error: /out of range/ },
  ];
  for (const c of cases) {
    const server = http.createServer((req, res) => {
      res.writeHead(200, { 'Content-Type': 'application/octet-stream' });  // no Content-Length
      res.end(c.body);
    });
    await new Promise((r) => server.listen(0, '127.0.0.1', r));
    const loader = new GeomipLoader();
    loader.model = c.model ?? 0;
    let sawDone = false;
    const error = await new Promise((resolve) => {
      loader.load(`http://127.0.0.1:${server.address().port}/p.gip`, (geometry) => {
        sawDone ||= geometry.userData.geomip.done;
        geometry.addEventListener('refine', (e) => { sawDone ||= e.done; });
      }, undefined, resolve);
      setTimeout(() => resolve(null), 20000);
    });
    server.close();
    check(error !== null && c.error.test(error.message) && !sawDone,
          `${pack} ${c.name}: onError (${error?.message}), never done`);
  }
  const prefix = await new GeomipLoader().parse(bytes.subarray(0, Math.floor(bytes.length * 0.6)));
  const info = prefix.userData.geomip;
  check(!info.done && info.total === bytes.length && info.status === 'truncated',
        `${pack}: parse() of a prefix: done ${info.done}, total ${info.total} of ${bytes.length}, ${info.status}`);
  const u = info.upright;  // a rotation: orthonormal columns, no translation
  let orthonormal = u[15] === 1 && u[12] === 0 && u[13] === 0 && u[14] === 0;
  for (let a = 0; a < 3; ++a)
    for (let b = 0; b < 3; ++b) {
      const dot = u[4 * a] * u[4 * b] + u[4 * a + 1] * u[4 * b + 1] + u[4 * a + 2] * u[4 * b + 2];
      orthonormal &&= Math.abs(dot - (a === b ? 1 : 0)) < 1e-9;
    }
  check(orthonormal, `${pack}: userData.geomip.upright is a rotation`);
}
console.log(failures === 0 ? 'three_loader_test: all checks passed' : `three_loader_test: ${failures} check(s) failed`);
process.exit(failures === 0 ? 0 : 1);
