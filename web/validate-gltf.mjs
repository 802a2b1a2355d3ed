// Khronos glTF validator over the files given: one line per file (errors, warnings), the
// messages of any error, exit 1 if a file has errors. Used by the physics-shape tests.
import { readFile } from 'node:fs/promises';
import { validateBytes } from 'gltf-validator';

let failed = false;
for (const path of process.argv.slice(2)) {
  const report = await validateBytes(new Uint8Array(await readFile(path)), { maxIssues: 1000 });
  const { numErrors, numWarnings, messages } = report.issues;
  console.log(`${path}: ${numErrors} errors, ${numWarnings} warnings`);
  for (const m of messages)
    if (m.severity === 0 || process.env.SPX_VALIDATOR_ALL) console.log(`  ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  failed ||= numErrors > 0;
}
process.exit(failed ? 1 : 0);
