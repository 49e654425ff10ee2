// Benchmark (not a test): full decode time of .gip packs by the WASM decoder (web/geomip.js over the WASM
// build), and of the same mesh Draco-encoded by Draco's own WASM decoder (npm draco3d), in one node
// process, best of REPS after warm-up. Run by scripts/bench-web, which adds the native figures and ratios.
//   node web_decode_bench.mjs CORE_JS MESH.obj DRACO_BITS PACK...
// Prints one line per measurement: "KEY ms" (keys: wasm:<pack>:core, wasm:<pack>:decode, draco:decode,
// draco:arrays), then notes.
import { readFileSync } from 'node:fs';
import { pathToFileURL } from 'node:url';
import draco3d from 'draco3d';
import { GeomipDecoder, loadCore } from '../../web/geomip.js';

const [coreJs, objPath, dracoBitsText, ...packs] = process.argv.slice(2);
const reps = Number(process.env.WEB_BENCH_REPS ?? 20);

function best(f) {
  for (let k = 0; k < 3; ++k) f();
  let t = Infinity;
  for (let k = 0; k < reps; ++k) {
    const t0 = performance.now();
    f();
    t = Math.min(t, performance.now() - t0);
  }
  return t;
}

const options = { coreUrl: pathToFileURL(coreJs).href };
const core = await loadCore(options);
for (const pack of packs) {
  const bytes = readFileSync(pack);
  const decoder = new GeomipDecoder(core);
  decoder.push(bytes);
  const check = decoder.decode();
  if (check.status !== 'ok') throw new Error(`${pack}: ${check.status}`);
  decoder.dispose();
  // Every repetition decodes the whole pack with a fresh decoder (a decoder that has seen the bytes keeps its
  // result: decoding them again costs nothing). The WASM call alone (grids stay in WASM memory), and decode()
  // with the copies into JS arrays; both include pushing the bytes into WASM memory (one copy).
  const coreMs = best(() => {
    const d = new GeomipDecoder(core);
    d.push(bytes);
    core._gip_decode(d.handle_, 1);
    d.dispose();
  });
  const decodeMs = best(() => {
    const d = new GeomipDecoder(core);
    d.push(bytes);
    d.decode();
    d.dispose();
  });
  console.log(`wasm:${pack}:core ${coreMs.toFixed(3)}`);
  console.log(`wasm:${pack}:decode ${decodeMs.toFixed(3)}`);
  console.log(`# ${pack}: ${bytes.length} bytes, ${check.models.length} model(s), ` +
              `${check.models[0].numPatches} patches of level ${check.models[0].level}`);
}

// Draco: encode the mesh with draco3d's encoder (position quantization DRACO_BITS over the largest extent,
// compression level 10 = speed 0, as baselines/draco_baseline), then time its decoder.
const text = readFileSync(objPath, 'utf8');
const positions = [], faces = [];
for (const line of text.split('\n')) {
  if (line.startsWith('v ')) positions.push(...line.trim().split(/\s+/).slice(1, 4).map(Number));
  else if (line.startsWith('f ')) {
    const idx = line.trim().split(/\s+/).slice(1).map((t) => parseInt(t, 10) - 1);
    for (let k = 1; k + 1 < idx.length; ++k) faces.push(idx[0], idx[k], idx[k + 1]);
  }
}
const encoderModule = await draco3d.createEncoderModule({});
const decoderModule = await draco3d.createDecoderModule({});
const builder = new encoderModule.MeshBuilder();
const mesh = new encoderModule.Mesh();
builder.AddFacesToMesh(mesh, faces.length / 3, new Uint32Array(faces));
builder.AddFloatAttributeToMesh(mesh, encoderModule.POSITION, positions.length / 3, 3,
                                new Float32Array(positions));
const encoder = new encoderModule.Encoder();
encoder.SetAttributeQuantization(encoderModule.POSITION, Number(dracoBitsText));
encoder.SetSpeedOptions(0, 0);
const out = new encoderModule.DracoInt8Array();
const size = encoder.EncodeMeshToDracoBuffer(mesh, out);
const drc = new Int8Array(size);
for (let i = 0; i < size; ++i) drc[i] = out.GetValue(i);

const dracoDecoder = new decoderModule.Decoder();
let vertices = 0;
const decodeDraco = (arrays) => {
  const buffer = new decoderModule.DecoderBuffer();
  buffer.Init(drc, drc.length);
  const decoded = new decoderModule.Mesh();
  const status = dracoDecoder.DecodeBufferToMesh(buffer, decoded);
  if (!status.ok()) throw new Error(`draco: ${status.error_msg()}`);
  if (arrays) {  // what a viewer needs: positions and the index list as typed arrays
    const n = decoded.num_points() * 3;
    const ptr = decoderModule._malloc(n * 4);
    dracoDecoder.GetAttributeDataArrayForAllPoints(
        decoded, dracoDecoder.GetAttribute(decoded, 0), decoderModule.DT_FLOAT32, n * 4, ptr);
    new Float32Array(decoderModule.HEAPF32.buffer, ptr, n).slice();
    decoderModule._free(ptr);
    const m = decoded.num_faces() * 3;
    const iptr = decoderModule._malloc(m * 4);
    dracoDecoder.GetTrianglesUInt32Array(decoded, m * 4, iptr);
    new Uint32Array(decoderModule.HEAPU32.buffer, iptr, m).slice();
    decoderModule._free(iptr);
  }
  vertices = decoded.num_points();
  decoderModule.destroy(decoded);
  decoderModule.destroy(buffer);
};
console.log(`draco:decode ${best(() => decodeDraco(false)).toFixed(3)}`);
console.log(`draco:arrays ${best(() => decodeDraco(true)).toFixed(3)}`);
console.log(`# draco: ${objPath} ${faces.length / 3} faces, ${vertices} vertices, ${size} bytes at ` +
            `${dracoBitsText} position bits, speed 0; node ${process.version}, best of ${reps}`);
