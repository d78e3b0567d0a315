// Khronos' glTF validator over the files given: prints each file's error and warning counts and
// every error; exit status 1 when any file has an error.
//
//     node tools/node/validate.js FILE.gltf|FILE.glb...
const validator = require('gltf-validator');
const fs = require('fs');
const path = require('path');

(async () => {
  let bad = 0;
  for (const f of process.argv.slice(2)) {
    const external = (uri) =>
      Promise.resolve(new Uint8Array(fs.readFileSync(path.join(path.dirname(f), decodeURIComponent(uri)))));
    const r = await validator.validateBytes(new Uint8Array(fs.readFileSync(f)), {
      uri: f,
      externalResourceFunction: external,
    });
    console.log(`${f}: ${r.issues.numErrors} errors, ${r.issues.numWarnings} warnings`);
    for (const m of r.issues.messages.filter((m) => m.severity === 0)) {
      console.log(`  ${m.code}: ${m.message} ${m.pointer || ''}`);
    }
    if (r.issues.numErrors > 0) bad = 1;
  }
  process.exit(bad);
})();
