// glTF written by geomip opened by others (issue 17): `geomip decode PACK -o x.glb` and `-o x.obj` of the same
// pack; three.js's GLTFLoader (npm three, under node) reads the GLB into one mesh whose vertex and triangle
// counts equal the OBJ's and whose positions equal the OBJ's within its printed precision, with a unit
// NORMAL per vertex; `assimp info` (Debian assimp-utils) counts the same vertices and faces; and the GLB read
// back as input (`geomip info --json`) gives the same counts and topology as the OBJ.
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
    const objFaces = objText.filter((l) => l.startsWith('f ')).length;

    const bytes = readFileSync(glb);
    const gltf = await new Promise((resolve, reject) =>
      new GLTFLoader().parse(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.length), '', resolve, reject));
    const meshes = [];
    gltf.scene.traverse((o) => { if (o.isMesh) meshes.push(o); });
    const g = meshes[0]?.geometry;
    const position = g?.getAttribute('position'), normal = g?.getAttribute('normal');
    const triangles = g?.index ? g.index.count / 3 : 0;
    check(meshes.length === 1 && position.count === objPositions.length && triangles === objFaces,
          `${name}: GLTFLoader reads ${meshes.length} mesh, ${position?.count} vertices, ${triangles} triangles (OBJ: ${objPositions.length}, ${objFaces})`);
    let worst = 0;
    for (let i = 0; i < Math.min(position.count, objPositions.length); ++i)
      for (let c = 0; c < 3; ++c) worst = Math.max(worst, Math.abs(position.array[3 * i + c] - objPositions[i][c]));
    check(worst <= 1e-5, `${name}: GLB positions equal the OBJ's (largest difference ${worst.toExponential(2)})`);
    let unit = 0;
    for (let i = 0; normal && i < normal.count; ++i)
      if (Math.abs(Math.hypot(normal.getX(i), normal.getY(i), normal.getZ(i)) - 1) < 1e-3) ++unit;
    check(normal && unit === normal.count, `${name}: ${unit} unit normals of ${position.count} vertices`);

    const assimp = execFileSync('assimp', ['info', glb], { encoding: 'utf8' });
    const field = (k) => Number((assimp.match(new RegExp(`^${k}:\\s+(\\d+)`, 'm')) ?? [])[1]);
    check(field('Vertices') === objPositions.length && field('Faces') === objFaces,
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
