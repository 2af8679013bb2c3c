// Validates glTF files with the Khronos glTF-Validator (npm package gltf-validator): prints each
// file's error and warning counts and its issues, exits 1 when any file has an error or a warning.
// Exits 77 when the validator is not installed (tools/setup installs it with npm).
'use strict';
const fs = require('fs');
let validator;
try {
  validator = require('gltf-validator');
} catch (e) {
  console.log('gltf-validator not installed');
  process.exit(77);
}
(async () => {
  let bad = 0;
  for (const file of process.argv.slice(2)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      uri: file,
      maxIssues: 50,
      externalResourceFunction: (uri) => Promise.reject(new Error('external resource ' + uri)),
    });
    const i = report.issues;
    console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints`);
    for (const m of i.messages) if (m.severity <= 1) console.log(`  ${m.code}: ${m.message} (${m.pointer || ''})`);
    if (i.numErrors > 0 || i.numWarnings > 0) bad++;
  }
  process.exit(bad ? 1 : 0);
})().catch((e) => {
  console.log('validator failed: ' + e);
  process.exit(1);
});
