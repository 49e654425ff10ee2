// glTF written by geomip opened by others (issue 17): `geomip decode PACK -o x.glb` and `-o x.obj` of the same
// pack. The GLB is the OBJ's surface with per-patch texture coordinates: the same triangles in the same order,
// seam vertices once per patch (so each has its patch's (u,v)). three.js's GLTFLoader (npm three, under node)
// reads one mesh whose every triangle corner lies within 1e-5 of the OBJ's, a unit NORMAL and a TEXCOORD_0
// in [0,1]² per vertex; `assimp info` (Debian assimp-utils) counts the GLB's vertices and the OBJ's faces; and
// the GLB read back as input (`geomip info --json`, which merges vertices at identical positions) gives the
// same counts and topology as the OBJ.
//   node gltf_interop_test.mjs GEOMIP_BINARY ONE_MODEL_PACK TWO_MODEL_PACK
import { execFileSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, readdirSync, readFileSync, rmSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';

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
    for (const f of readdirSync(dir).filter((f) => f.endsWith('.glb')).sort())
      pairs.push([`${path.basename(pack, '.gip')}/${f.slice(0, -4)}`, path.join(dir, f), path.join(dir, f.replace(/glb$/, 'obj'))]);
  }
  check(pairs.length === packs.length + 1, `${pairs.length} models decoded from ${packs.length} packs`);
  for (const [name, glb, obj] of pairs) {
    const objText = readFileSync(obj, 'utf8').split('\n');
    const objPositions = objText.filter((l) => l.startsWith('v ')).map((l) => l.split(/\s+/).slice(1, 4).map(Number));
    const objTriangles = objText.filter((l) => l.startsWith('f ')).map((l) => l.split(/\s+/).slice(1, 4).map((w) => parseInt(w, 10) - 1));
    const objFaces = objTriangles.length;

    const bytes = readFileSync(glb);
    const gltf = await new Promise((resolve, reject) =>
      new GLTFLoader().parse(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.length), '', resolve, reject));
    const meshes = [];
    gltf.scene.traverse((o) => { if (o.isMesh) meshes.push(o); });
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
  }
} finally {
  rmSync(tmp, { recursive: true, force: true });
}
console.log(failures === 0 ? 'gltf_interop_test: all checks passed' : `gltf_interop_test: ${failures} check(s) failed`);
process.exit(failures === 0 ? 0 : 1);
