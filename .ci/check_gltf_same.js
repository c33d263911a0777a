// Checks that an export adds no glTF-Validator message to those of the avatar it was driven on
// (an avatar someone published may carry errors of its own, which the export keeps as they are).
// Usage: node .ci/check_gltf_same.js AVATAR.gltf|glb EXPORT.glb   (gltf-validator where Node finds it)
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

const codes = async (file) => {
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: file,
    maxIssues: 100000,
    externalResourceFunction: (uri) =>
      Promise.resolve(new Uint8Array(fs.readFileSync(path.join(path.dirname(file), decodeURIComponent(uri))))),
  });
  const seen = {};
  for (const m of report.issues.messages) seen[`${m.code} (severity ${m.severity})`] = true;
  console.log(`${file}: ${report.issues.numErrors} errors, ${report.issues.numWarnings} warnings`);
  return seen;
};

(async () => {
  const [avatar, exported] = process.argv.slice(2);
  const before = await codes(avatar);
  const after = await codes(exported);
  const added = Object.keys(after).filter((c) => !before[c]);
  for (const c of added) console.log(`  added by the export: ${c}`);
  process.exit(added.length ? 1 : 0);
})();
