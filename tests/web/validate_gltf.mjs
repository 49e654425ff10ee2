// The Khronos glTF validator (npm gltf-validator, the official one compiled to JS) on glTF / GLB files: prints
// each file's errors, warnings and infos with their JSON pointers, and exits 1 when any file has an error (2
// when a file cannot be read or is not glTF at all). External buffers and images are read beside the file.
//   node tests/web/validate_gltf.mjs FILE.glb|FILE.gltf...
// validate_file() is what gltf_validator_test.mjs uses.
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import validator from 'gltf-validator';

const kSeverity = ['error', 'warning', 'info', 'hint'];

/// The validator's report of `file`: { numErrors, numWarnings, numInfos, numHints, messages: [{ code,
/// message, severity, pointer }] } (severity 0 error … 3 hint), every issue listed (no cap).
export async function validate_file(file) {
  const bytes = await readFile(file);
  const report = await validator.validateBytes(new Uint8Array(bytes), {
    uri: path.basename(file),
    maxIssues: 0,
    writeTimestamp: false,
    externalResourceFunction: (uri) =>
      readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
  });
  return report.issues;
}

/// One line per issue: "  error ACCESSOR_NON_UNIT /accessors/1: ..." (a validator message as it wrote it).
export function issue_lines(issues) {
  return issues.messages.map((m) => `  ${kSeverity[m.severity] ?? m.severity} ${m.code} ${m.pointer ?? ''}: ${m.message}`);
}

export function summary(issues) {
  return `${issues.numErrors} errors, ${issues.numWarnings} warnings, ${issues.numInfos} infos, ${issues.numHints} hints`;
}

if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const files = process.argv.slice(2);
  if (files.length === 0) {
    console.error(`glTF validator ${validator.version()}: usage: node validate_gltf.mjs FILE.glb|FILE.gltf...`);
    process.exit(2);
  }
  let status = 0;
  for (const file of files) {
    try {
      const issues = await validate_file(file);
      console.log(`${file}: ${summary(issues)}`);
      for (const line of issue_lines(issues)) console.log(line);
      if (issues.numErrors > 0) status = Math.max(status, 1);
    } catch (e) {
      console.log(`${file}: not validated: ${e?.message ?? e}`);
      status = 2;
    }
  }
  process.exit(status);
}
