// glTF written by geomip opened by others (issue 17): `geomip decode PACK -o x.glb` and `-o x.obj` of the same
// pack. The GLB is the OBJ's surface with per-patch texture coordinates: the same triangles in the same order,
// seam vertices once per patch (so each has its patch's (u,v)). three.js's GLTFLoader (npm three, under node)
// reads one mesh whose every triangle corner lies within 1e-5 of the OBJ's, a unit NORMAL and a TEXCOORD_0
// in [0,1]² per vertex; `assimp info` (Debian assimp-utils) counts the GLB's vertices and the OBJ's faces; and
// the GLB read back as input (`geomip info --json`, which merges vertices at identical positions) gives the
// same counts and topology as the OBJ.
// `decode --draco` (KHR_draco_mesh_compression): the same GLTFLoader, its Draco primitives decoded by Draco's
// own WASM decoder (npm draco3d, plugged in as DRACOLoader plugs in its worker), gives the plain GLB's
// triangles — each Draco vertex matched to the plain vertex with its TEXCOORD_0 and position within the
// quantization steps, every triangle the same three matched vertices in the same orientation, normals within
// 1° — in a smaller file; and `geomip info` reads it back with the OBJ's counts.
//   node gltf_interop_test.mjs GEOMIP_BINARY ONE_MODEL_PACK TWO_MODEL_PACK
import { execFileSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, readdirSync, readFileSync, rmSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { BufferAttribute, BufferGeometry } from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import draco3d from 'draco3d';

// What three's DRACOLoader does in its worker (decodeGeometry), with draco3d's decoder in this process: the
// loader GLTFLoader.setDRACOLoader() takes (preload + decodeDracoFile).
const draco = await draco3d.createDecoderModule({});
const dracoLoader = {
  preload() { return this; },
  decodeDracoFile(buffer, onLoad, attributeIDs, attributeTypes, _colorSpace, onError) {
    const decoder = new draco.Decoder();
    const mesh = new draco.Mesh();
    try {
      const bytes = new Int8Array(buffer);
      const status = decoder.DecodeArrayToMesh(bytes, bytes.byteLength, mesh);
      if (!status.ok()) throw new Error(`draco3d: ${status.error_msg()}`);
      const geometry = new BufferGeometry();
      const count = mesh.num_faces() * 3;
      let ptr = draco._malloc(count * 4);
      decoder.GetTrianglesUInt32Array(mesh, count * 4, ptr);
      geometry.setIndex(new BufferAttribute(new Uint32Array(draco.HEAPU32.buffer, ptr, count).slice(), 1));
      draco._free(ptr);
      for (const [name, id] of Object.entries(attributeIDs)) {
        if (attributeTypes[name] !== 'Float32Array') throw new Error(`${name}: ${attributeTypes[name]}, not float`);
        const attribute = decoder.GetAttributeByUniqueId(mesh, id);
        const size = attribute.num_components(), n = mesh.num_points() * size;
        ptr = draco._malloc(n * 4);
        decoder.GetAttributeDataArrayForAllPoints(mesh, attribute, draco.DT_FLOAT32, n * 4, ptr);
        geometry.setAttribute(name, new BufferAttribute(new Float32Array(draco.HEAPF32.buffer, ptr, n).slice(), size));
        draco._free(ptr);
      }
      onLoad(geometry);
    } catch (e) {
      onError(e);
    } finally {
      draco.destroy(mesh);
      draco.destroy(decoder);
    }
  },
};

async function loadGlb(file, withDraco) {
  const bytes = readFileSync(file);
  const loader = new GLTFLoader();
  if (withDraco) loader.setDRACOLoader(dracoLoader);
  const gltf = await new Promise((resolve, reject) =>
    loader.parse(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.length), '', resolve, reject));
  const meshes = [];
  gltf.scene.traverse((o) => { if (o.isMesh) meshes.push(o); });
  return meshes;
}

const [geomip, ...packs] = process.argv.slice(2);
let failures = 0;
const check = (ok, what) => { console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`); if (!ok) ++failures; };
const tmp = mkdtempSync(path.join(os.tmpdir(), 'geomip-gltf-'));
try {
  const pairs = [];
  for (const pack of packs) {  // several models: one file per model, <stem>.<model>.<ext>
    const dir = path.join(tmp, path.basename(pack, '.gip'));
    mkdirSync(dir);
    execFileSync(geomip, ['decode', pack, '-o', path.join(dir, 'm.glb')], { stdio: 'ignore' });
    execFileSync(geomip, ['decode', pack, '-o', path.join(dir, 'm.obj')], { stdio: 'ignore' });
    mkdirSync(path.join(dir, 'draco'));
    execFileSync(geomip, ['decode', pack, '--draco', '-o', path.join(dir, 'draco', 'm.glb')], { stdio: 'ignore' });
    for (const f of readdirSync(dir).filter((f) => f.endsWith('.glb')).sort())
      pairs.push([`${path.basename(pack, '.gip')}/${f.slice(0, -4)}`, path.join(dir, f), path.join(dir, f.replace(/glb$/, 'obj'))]);
  }
  check(pairs.length === packs.length + 1, `${pairs.length} models decoded from ${packs.length} packs`);
  for (const [name, glb, obj] of pairs) {
    const objText = readFileSync(obj, 'utf8').split('\n');
    const objPositions = objText.filter((l) => l.startsWith('v ')).map((l) => l.split(/\s+/).slice(1, 4).map(Number));
    const objTriangles = objText.filter((l) => l.startsWith('f ')).map((l) => l.split(/\s+/).slice(1, 4).map((w) => parseInt(w, 10) - 1));
    const objFaces = objTriangles.length;

    const meshes = await loadGlb(glb, false);
    const g = meshes[0]?.geometry;
    const position = g?.getAttribute('position'), normal = g?.getAttribute('normal'), uv = g?.getAttribute('uv');
    const triangles = g?.index ? g.index.count / 3 : 0;
    check(meshes.length === 1 && position.count >= objPositions.length && triangles === objFaces,
          `${name}: GLTFLoader reads ${meshes.length} mesh, ${position?.count} vertices (OBJ: ${objPositions.length} welded), ${triangles} triangles (OBJ: ${objFaces})`);
    let worst = 0;
    for (let t = 0; t < Math.min(triangles, objFaces); ++t)
      for (let k = 0; k < 3; ++k) {
        const v = g.index.array[3 * t + k], o = objPositions[objTriangles[t][k]];
        for (let c = 0; c < 3; ++c) worst = Math.max(worst, Math.abs(position.array[3 * v + c] - o[c]));
      }
    check(worst <= 1e-5, `${name}: every GLB triangle corner equals the OBJ's (largest difference ${worst.toExponential(2)})`);
    let unit = 0;
    for (let i = 0; normal && i < normal.count; ++i)
      if (Math.abs(Math.hypot(normal.getX(i), normal.getY(i), normal.getZ(i)) - 1) < 1e-3) ++unit;
    check(normal && unit === position.count, `${name}: ${unit} unit normals of ${position.count} vertices`);
    let inSquare = 0;
    for (let i = 0; uv && i < uv.count; ++i)
      if (uv.getX(i) >= 0 && uv.getX(i) <= 1 && uv.getY(i) >= 0 && uv.getY(i) <= 1) ++inSquare;
    check(uv && inSquare === position.count, `${name}: ${inSquare} TEXCOORD_0 in [0,1]² of ${position.count} vertices`);

    const assimp = execFileSync('assimp', ['info', glb], { encoding: 'utf8' });
    const field = (k) => Number((assimp.match(new RegExp(`^${k}:\\s+(\\d+)`, 'm')) ?? [])[1]);
    check(field('Vertices') === position.count && field('Faces') === objFaces,
          `${name}: assimp info: ${field('Vertices')} vertices, ${field('Faces')} faces`);

    const info = (file) => JSON.parse(execFileSync(geomip, ['info', file, '--json'], { encoding: 'utf8' }));
    const a = info(glb), b = info(obj);
    const keys = ['vertices', 'faces', 'edges', 'boundary_loops', 'components', 'genus', 'manifold'];
    check(keys.every((k) => a[k] === b[k]),
          `${name}: geomip info of the GLB as input equals the OBJ's (${keys.map((k) => `${k} ${a[k]}`).join(', ')})`);

    // The Draco GLB of the same model.
    const dglb = path.join(path.dirname(glb), 'draco', path.basename(glb));
    const dmeshes = await loadGlb(dglb, true);
    const d = dmeshes[0]?.geometry;
    const dpos = d?.getAttribute('position'), dnormal = d?.getAttribute('normal'), duv = d?.getAttribute('uv');
    check(dmeshes.length === 1 && dpos?.count === position.count && d.index?.count === 3 * triangles && dnormal && duv,
          `${name} (Draco): GLTFLoader + draco3d read ${dmeshes.length} mesh, ${dpos?.count} vertices, ${d?.index ? d.index.count / 3 : 0} triangles, normals and uv`);
    if (dpos?.count === position.count && d.index?.count === 3 * triangles) {
      // Quantization steps: positions 14 bits over the largest extent, texture coordinates 12 bits.
      let extent = 0;
      for (let c = 0; c < 3; ++c) {
        let lo = Infinity, hi = -Infinity;
        for (let i = 0; i < position.count; ++i) { const x = position.array[3 * i + c]; lo = Math.min(lo, x); hi = Math.max(hi, x); }
        extent = Math.max(extent, hi - lo);
      }
      const positionTolerance = Math.sqrt(3) / 2 * extent / (2 ** 14 - 1) * 1.01, uvTolerance = 1 / (2 ** 12 - 1);
      const match = new Int32Array(dpos.count).fill(-1);
      let worstPosition = 0, worstAngle = 0;
      for (let i = 0; i < dpos.count; ++i) {
        let best = -1, bestDistance = Infinity;
        for (let k = 0; k < position.count; ++k) {
          if (Math.abs(duv.getX(i) - uv.getX(k)) > uvTolerance || Math.abs(duv.getY(i) - uv.getY(k)) > uvTolerance) continue;
          const dist = Math.hypot(dpos.getX(i) - position.getX(k), dpos.getY(i) - position.getY(k), dpos.getZ(i) - position.getZ(k));
          if (dist < bestDistance) { bestDistance = dist; best = k; }
        }
        match[i] = best;
        worstPosition = Math.max(worstPosition, bestDistance);
        if (best >= 0) {
          const dot = dnormal.getX(i) * normal.getX(best) + dnormal.getY(i) * normal.getY(best) + dnormal.getZ(i) * normal.getZ(best);
          worstAngle = Math.max(worstAngle, Math.acos(Math.min(1, dot)) * 180 / Math.PI);
        }
      }
      check(worstPosition <= positionTolerance,
            `${name} (Draco): every vertex within ${worstPosition.toExponential(2)} of the plain GLB's vertex with its uv (step bound ${positionTolerance.toExponential(2)})`);
      check(worstAngle <= 1, `${name} (Draco): normals within ${worstAngle.toFixed(3)}° of the plain GLB's`);
      // Plain vertices with the same position and uv (the patches' shared corners) are one vertex here.
      const sameVertex = new Map(), klass = new Int32Array(position.count);
      for (let k = 0; k < position.count; ++k) {
        const id = [position.getX(k), position.getY(k), position.getZ(k), uv.getX(k), uv.getY(k)].join(',');
        if (!sameVertex.has(id)) sameVertex.set(id, k);
        klass[k] = sameVertex.get(id);
      }
      const key = (a, b, c) => { const m = Math.min(a, b, c); return m === a ? `${a},${b},${c}` : m === b ? `${b},${c},${a}` : `${c},${a},${b}`; };
      const plainTriangles = new Map();
      for (let t = 0; t < triangles; ++t) {
        const k = key(klass[g.index.array[3 * t]], klass[g.index.array[3 * t + 1]], klass[g.index.array[3 * t + 2]]);
        plainTriangles.set(k, (plainTriangles.get(k) ?? 0) + 1);
      }
      let same = 0;
      for (let t = 0; t < triangles; ++t) {
        const m = (j) => { const v = match[d.index.array[3 * t + j]]; return v < 0 ? -1 : klass[v]; };
        const k = key(m(0), m(1), m(2));
        const left = plainTriangles.get(k) ?? 0;
        if (left > 0) { plainTriangles.set(k, left - 1); ++same; }
      }
      check(same === triangles, `${name} (Draco): ${same} of ${triangles} triangles are the plain GLB's, same orientation`);
    }
    const plainBytes = readFileSync(glb).length, dracoBytes = readFileSync(dglb).length;
    check(dracoBytes < plainBytes / 2, `${name} (Draco): ${dracoBytes} bytes, ${(dracoBytes / plainBytes).toFixed(3)} of the plain GLB's ${plainBytes}`);
    const c = info(dglb);
    check(keys.every((k) => c[k] === b[k]),
          `${name} (Draco): geomip info of the Draco GLB as input equals the OBJ's (${keys.map((k) => `${k} ${c[k]}`).join(', ')})`);
  }
} finally {
  rmSync(tmp, { recursive: true, force: true });
}
console.log(failures === 0 ? 'gltf_interop_test: all checks passed' : `gltf_interop_test: ${failures} check(s) failed`);
process.exit(failures === 0 ? 0 : 1);
