// Every kind of glTF geomip writes passes the Khronos glTF validator (npm gltf-validator) with no error and
// no warning: `decode` to .glb and .gltf (normal maps and a hole mask, the view frame as the node's matrix, a
// prefix before the normal maps, a coarser level split by the fixed rule, two models, a geometry-only pack, a
// format-3 pack without a frame), `decode --draco` (GLB and JSON), `repair -o .glb/.gltf` (write_mesh's
// vertex normals) and `remesh --glb [--draco]`. Each file is also checked to be the case it stands for
// (matrix or none, Draco or plain, NORMAL, TEXCOORD_0), so the validator sees every feature. The infos the
// validator may give are listed: TEXCOORD_0 unused (no material: it is each patch's (u,v) for the user's
// textures) and, for Draco, the extension it cannot validate and the buffer view only the extension uses.
// The check cannot pass vacuously: the same predicate, and validate_gltf.mjs's exit status, fail on a GLB
// broken four ways (a normal off unit length, POSITION without bounds, an index past the vertices, a
// truncated file).
//   node gltf_validator_test.mjs GEOMIP_BINARY SOURCE_DIR
import { execFileSync, spawnSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, readdirSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { issue_lines, summary, validate_file } from './validate_gltf.mjs';

const [geomip, source] = process.argv.slice(2);
const here = path.dirname(fileURLToPath(import.meta.url));
const data = (f) => path.join(source, 'tests', 'data', f);
let failures = 0;
const check = (ok, what) => { console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`); if (!ok) ++failures; };

const kDraco = 'KHR_draco_mesh_compression';
/// The infos a geomip file may carry (see above); anything else of severity info is printed, not failed.
const expected_info = (m) =>
  (m.code === 'UNUSED_OBJECT' && m.pointer === '/meshes/0/primitives/0/attributes/TEXCOORD_0') ||
  (m.code === 'UNSUPPORTED_EXTENSION' && m.message.includes(kDraco)) ||
  (m.code === 'UNUSED_OBJECT' && /^\/bufferViews\/\d+$/.test(m.pointer));

/// What the test requires of a validator report: no error and no warning.
const passes = (issues) => issues.numErrors === 0 && issues.numWarnings === 0;

/// The JSON of a .gltf or .glb file, and for a GLB its BIN chunk.
function parse(bytes) {
  if (bytes.subarray(0, 4).toString('latin1') !== 'glTF') return { json: JSON.parse(bytes.toString('utf8')) };
  const length = bytes.readUInt32LE(12);
  const json = JSON.parse(bytes.subarray(20, 20 + length).toString('utf8'));
  const bin = bytes.subarray(20 + length + 8, 20 + length + 8 + bytes.readUInt32LE(20 + length));
  return { json, bin };
}

/// A GLB of `json` and `bin`, each chunk padded to 4 bytes as the specification requires.
function glb(json, bin) {
  let text = Buffer.from(JSON.stringify(json));
  text = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
  const header = Buffer.alloc(12), jsonHead = Buffer.alloc(8), binHead = Buffer.alloc(8);
  header.write('glTF', 0, 'latin1');
  header.writeUInt32LE(2, 4);
  header.writeUInt32LE(12 + 8 + text.length + 8 + bin.length, 8);
  jsonHead.writeUInt32LE(text.length, 0);
  jsonHead.write('JSON', 4, 'latin1');
  binHead.writeUInt32LE(bin.length, 0);
  binHead.write('BIN\0', 4, 'latin1');
  return Buffer.concat([header, jsonHead, text, binHead, bin]);
}

const tmp = mkdtempSync(path.join(os.tmpdir(), 'geomip-gltf-validator-'));
try {
  const run = (...args) => execFileSync(geomip, args, { stdio: ['ignore', 'ignore', 'inherit'] });
  const out = (f) => path.join(tmp, f);
  // [file pattern, what it is: { matrix, draco, normal, uv }]
  const cases = [];
  const add = (dir, props) => {
    for (const f of readdirSync(out(dir)).filter((f) => /\.gl(b|tf)$/.test(f)).sort())
      cases.push([path.join(dir, f), props]);
  };
  const decode = (dir, pack, ...args) => {
    mkdirSync(out(dir));
    for (const ext of ['glb', 'gltf']) run('decode', data(pack), ...args, '-o', out(`${dir}/m.${ext}`), '--quiet');
  };
  const textured = { normal: true, uv: true };
  decode('bunny', 'web-bunny-l4.gip');                 // normal maps, hole mask, a view frame
  add('bunny', { ...textured, matrix: true, draco: false });
  decode('bunny-draco', 'web-bunny-l4.gip', '--draco');
  add('bunny-draco', { ...textured, matrix: true, draco: true });
  decode('bunny-prefix', 'web-bunny-l4.gip', '--bytes', '320');  // geometry passes only: the mesh's normals
  add('bunny-prefix', { ...textured, matrix: true, draco: false });
  decode('bunny-level2', 'web-bunny-l4.gip', '--level', '2', '--quad-split', 'fixed', '--no-untangle');
  add('bunny-level2', { ...textured, matrix: true, draco: false });
  decode('horse-pig', 'web-horse-pig-l4.gip');          // two models: m.horse.glb, m.pig.glb, ...
  add('horse-pig', { ...textured, matrix: true, draco: false });
  decode('horse-pig-draco', 'web-horse-pig-l4.gip', '--draco=10');
  add('horse-pig-draco', { ...textured, matrix: true, draco: true });
  decode('geometry-only', 'web-bunny-l6-geometry.gip'); // no normal maps, no frame
  add('geometry-only', { ...textured, matrix: false, draco: false });
  decode('format3', 'web-horse-pig-l4-v3.gip');         // format 3: no frame
  add('format3', { ...textured, matrix: false, draco: false });
  mkdirSync(out('repair'));
  for (const ext of ['glb', 'gltf']) run('repair', path.join(source, 'data', 'spot.obj'), '-o', out(`repair/spot.${ext}`), '--quiet');
  add('repair', { normal: true, uv: false, matrix: false, draco: false });
  run('remesh', path.join(source, 'data', 'spot.obj'), '--level', '3', '--glb', '-o', out('remesh'), '--quiet');
  add('remesh', { ...textured, matrix: false, draco: false });
  run('remesh', path.join(source, 'data', 'spot.obj'), '--level', '3', '--glb', '--draco', '-o', out('remesh-draco'), '--quiet');
  add('remesh-draco', { ...textured, matrix: false, draco: true });
  // 4 bunny decodes and 2 more of one model × (.glb, .gltf), 2 of two models × 2 × 2, repair × 2, remesh × 2.
  check(cases.length === 26, `${cases.length} glTF files written (26 expected)`);

  for (const [file, want] of cases) {
    const issues = await validate_file(out(file));
    const unexpected = issues.messages.filter((m) => m.severity <= 1 || (m.severity === 2 && !expected_info(m)));
    const { json } = parse(readFileSync(out(file)));
    const prim = json.meshes?.[0]?.primitives?.[0] ?? {};
    const node = json.nodes?.[json.scenes?.[json.scene ?? 0]?.nodes?.[0]] ?? {};
    const got = {
      matrix: Array.isArray(node.matrix),
      draco: Boolean(prim.extensions?.[kDraco]) && (json.extensionsRequired ?? []).includes(kDraco),
      normal: 'NORMAL' in (prim.attributes ?? {}),
      uv: 'TEXCOORD_0' in (prim.attributes ?? {}),
    };
    const position = json.accessors?.[prim.attributes?.POSITION];
    const bounds = position?.min?.length === 3 && position?.max?.length === 3;
    check(passes(issues) && Object.keys(want).every((k) => got[k] === want[k]) && bounds,
          `${file}: ${summary(issues)}; ${Object.entries(got).filter(([, v]) => v).map(([k]) => k).join(' ')}` +
          `${bounds ? ' POSITION-bounds' : ''} (expected ${Object.keys(got).filter((k) => want[k]).join(' ')})` +
          (unexpected.length ? '\n' + issue_lines({ messages: unexpected }).join('\n') : ''));
  }

  // Four broken copies of a good GLB: the validator must report each, the same predicate must fail it, and
  // validate_gltf.mjs must exit 1 on it (0 on the good file).
  const good = readFileSync(out('bunny/m.glb'));
  const { json, bin } = parse(good);
  const attributes = json.meshes[0].primitives[0].attributes;
  const offset = (accessor) => json.bufferViews[json.accessors[accessor].bufferView].byteOffset;
  const broken = [];
  {
    const b = Buffer.from(bin);
    const at = offset(attributes.NORMAL);
    for (let k = 0; k < 3; ++k) b.writeFloatLE(b.readFloatLE(at + 4 * k) * 1.01, at + 4 * k);
    broken.push(['normal-off-unit', glb(json, b), 'ACCESSOR_VECTOR3_NON_UNIT']);
  }
  {
    const j = structuredClone(json);
    delete j.accessors[attributes.POSITION].min;
    delete j.accessors[attributes.POSITION].max;
    broken.push(['position-without-bounds', glb(j, bin), 'MESH_PRIMITIVE_POSITION_ACCESSOR_WITHOUT_BOUNDS']);
  }
  {
    const b = Buffer.from(bin);
    b.writeUInt32LE(json.accessors[attributes.POSITION].count + 7, offset(json.meshes[0].primitives[0].indices));
    broken.push(['index-past-the-vertices', glb(json, b), 'ACCESSOR_INDEX_OOB']);
  }
  broken.push(['truncated', good.subarray(0, good.length - 4), 'GLB_UNEXPECTED_END_OF_CHUNK_DATA']);
  const cli = (file) => spawnSync(process.execPath, [path.join(here, 'validate_gltf.mjs'), file], { encoding: 'utf8' });
  check(cli(out('bunny/m.glb')).status === 0, 'validate_gltf.mjs exits 0 on the good GLB');
  for (const [name, bytes, code] of broken) {
    const file = out(`broken-${name}.glb`);
    writeFileSync(file, bytes);
    const issues = await validate_file(file);
    const codes = [...new Set(issues.messages.filter((m) => m.severity === 0).map((m) => m.code))];
    check(!passes(issues) && codes.includes(code), `broken (${name}): ${summary(issues)}: ${codes.join(', ')} (expected ${code})`);
    const status = cli(file).status;
    check(status === 1, `broken (${name}): validate_gltf.mjs exits ${status} (expected 1)`);
  }
} finally {
  rmSync(tmp, { recursive: true, force: true });
}
console.log(failures === 0 ? 'gltf_validator_test: all checks passed' : `gltf_validator_test: ${failures} check(s) failed`);
process.exit(failures === 0 ? 0 : 1);
