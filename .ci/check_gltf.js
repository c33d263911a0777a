// Validates binary glTF files with the Khronos glTF-Validator (npm package gltf-validator):
// prints each file's counts and first messages; exits 1 if any file has an error.
// Usage: node .ci/check_gltf.js FILE.glb...
const fs = require('fs');
const validator = require('gltf-validator');

(async () => {
  let failed = 0;
  for (const path of process.argv.slice(2)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(path)));
    const issues = report.issues;
    console.log(`${path}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ${issues.numInfos} infos`);
    for (const m of issues.messages.slice(0, 10)) {
      console.log(`  ${m.severity} ${m.code} ${m.pointer || ''}: ${m.message}`);
    }
    if (issues.numErrors > 0) failed++;
  }
  process.exit(failed ? 1 : 0);
})();
