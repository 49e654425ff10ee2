// The WASM decoder (web/geomip.js over scripts/build-wasm's build) against the native codec: for every byte
// prefix 0..size of each pack, pushed one byte at a time into one streaming decoder, decode() gives exactly
// the native codec::decode_pack result of the same prefix — status, bytes used, levels, every float of every
// grid (positions, normals) and every hole-mask byte, compared through two 32-bit hashes of the canonical
// word list (tests/web/pack_prefix_hashes.cpp); the first differing prefix is then compared word by word.
//   node wasm_decoder_test.mjs [--stride K] CORE_JS NATIVE_TOOL PACK:MIN_MODELS:FEATURES...
// --stride K: only every K-th prefix (and the last); for the committed web/dist build.
// FEATURES: letters the full decode must show, n = normal maps, h = hole masks (so the test is not vacuous).
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { pathToFileURL } from 'node:url';
import { createDecoder } from '../../web/geomip.js';

const args = process.argv.slice(2);
let stride = 1;
if (args[0] === '--stride') { stride = Number(args[1]); args.splice(0, 2); }
const [coreJs, nativeTool, ...packs] = args;
if (!coreJs || !nativeTool || packs.length === 0) {
  console.error('usage: node wasm_decoder_test.mjs [--stride K] CORE_JS NATIVE_TOOL PACK:MIN_MODELS:FEATURES...');
  process.exit(2);
}
const kStatusCode = { 'ok': 0, 'truncated': 1, 'corrupt': 2, 'unsupported-version': 3, 'invalid-argument': 4 };
const wasmBinary = readFileSync(coreJs.replace(/\.js$/, '.wasm'));

function canonicalWords(result) {
  const w = [kStatusCode[result.status], result.bytesUsed, result.chunksDecoded, result.models.length];
  for (const m of result.models) {
    w.push(m.numPatches, m.level, m.normalLevel, m.holeMaskLevel, m.detailLevel, m.geometryPasses);
    for (let p = 0; p < m.numPatches; ++p) {
      for (const v of new Uint32Array(m.geometry[p].buffer)) w.push(v);
      if (p < m.normals.length) for (const v of new Uint32Array(m.normals[p].buffer)) w.push(v);
      if (p < m.holeMask.length) for (const b of m.holeMask[p]) w.push(b);
    }
  }
  return Uint32Array.from(w, (x) => x >>> 0);
}

function canonicalHashes(words) {
  let h1 = 2166136261, h2 = 0x9747b28c;
  for (const x of words) {
    h1 = Math.imul(h1 ^ x, 16777619);
    const k = (h2 ^ x) >>> 0;
    h2 = (Math.imul((k << 13) | (k >>> 19), 0x85ebca6b) + 1) | 0;
  }
  const hex = (h) => (h >>> 0).toString(16).padStart(8, '0');
  return `${hex(h1)} ${hex(h2)}`;
}

let failures = 0;
{
  // push() takes bytes only (found by a review on 2026-12-06: push(123) appended 123 zero bytes, push('abc')
  // and push(null) were ignored, push(-1) threw a raw RangeError): anything else is a GeomipError
  // 'invalid-argument' and changes nothing.
  const decoder = await createDecoder({ coreUrl: pathToFileURL(coreJs).href, wasmBinary });
  decoder.push(new Uint8Array([1, 2, 3]));
  for (const bad of [123, -1, 1e10, 'abc', null, undefined, {}, [1, 2]]) {
    let status = null;
    try {
      decoder.push(bad);
    } catch (e) {
      status = e.status ?? `${e.name}: ${e.message}`;
    }
    if (status !== 'invalid-argument' || decoder.size !== 3) {
      console.error(`push(${JSON.stringify(bad)}): ${status}, size ${decoder.size} (want invalid-argument, 3)`);
      ++failures;
    }
  }
  decoder.push(new DataView(new ArrayBuffer(2)));
  decoder.push(new ArrayBuffer(1));
  if (decoder.size !== 6) {
    console.error(`a DataView and an ArrayBuffer pushed: size ${decoder.size}, want 6`);
    ++failures;
  }
  decoder.dispose();
}
for (const spec of packs) {
  const [pack, minModelsText, features = ''] = spec.split(':');
  const bytes = readFileSync(pack);
  const native = execFileSync(nativeTool, [pack], { maxBuffer: 1 << 28 }).toString().trim().split('\n');
  if (native.length !== bytes.length + 1) throw new Error(`${pack}: native tool gave ${native.length} lines`);
  const decoder = await createDecoder({ coreUrl: pathToFileURL(coreJs).href, wasmBinary });
  let mismatch = -1, withModels = 0, last = null;
  let checked = 0;
  for (let n = 0, pushed = 0; n <= bytes.length; ++n) {
    if (n % stride !== 0 && n !== bytes.length) continue;
    decoder.push(bytes.subarray(pushed, n));
    pushed = n;
    ++checked;
    const result = decoder.decode();
    const line = `${n} ${kStatusCode[result.status]} ${canonicalHashes(canonicalWords(result))}`;
    if (result.models.length > 0) ++withModels;
    last = result;
    if (line !== native[n]) { mismatch = n; console.error(`wasm: ${line}\nnative: ${native[n]}`); break; }
  }
  if (mismatch >= 0) {
    const fresh = await createDecoder({ coreUrl: pathToFileURL(coreJs).href, wasmBinary });
    fresh.push(bytes.subarray(0, mismatch));
    const ours = canonicalWords(fresh.decode());
    const dump = execFileSync(nativeTool, [pack, '--dump', String(mismatch)], { maxBuffer: 1 << 28 });
    const theirs = new Uint32Array(dump.buffer, dump.byteOffset, dump.length / 4);
    let at = 0;
    while (at < ours.length && at < theirs.length && ours[at] === theirs[at]) ++at;
    console.error(`${pack}: FAIL at prefix ${mismatch} bytes: first differing word ${at} ` +
                  `(wasm ${ours[at]}, native ${theirs[at]}; ${ours.length} vs ${theirs.length} words)`);
    ++failures;
    continue;
  }
  const complaints = [];
  if (last.status !== 'ok') complaints.push(`full decode status ${last.status}`);
  if (last.models.length < Number(minModelsText)) complaints.push(`${last.models.length} models`);
  if (features.includes('n') && !last.models.every((m) => m.normals.length === m.numPatches))
    complaints.push('no normal maps');
  if (features.includes('h') && !last.models.some((m) => m.holeMask.length > 0)) complaints.push('no hole mask');
  if (complaints.length > 0) {
    console.error(`${pack}: the fixture does not exercise what it should: ${complaints.join(', ')}`);
    ++failures;
    continue;
  }
  console.log(`${pack}: ${checked} prefixes (0..${bytes.length} bytes, ${withModels} with models, ` +
              `${last.models.length} models) bit-identical to the native decoder`);
}
process.exit(failures === 0 ? 0 : 1);
