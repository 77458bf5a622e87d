// Validate .glb files with the Khronos glTF validator; print one JSON report per file.
// Usage: node tests/gltf_validate.js MODULE_DIR FILE.glb...
const fs = require('fs');
const path = require('path');
const validator = require(path.join(process.argv[2], 'gltf-validator'));

async function main() {
  for (const file of process.argv.slice(3)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)));
    const issues = report.issues;
    console.log(JSON.stringify({
      file,
      errors: issues.numErrors,
      warnings: issues.numWarnings,
      messages: issues.messages.filter((m) => m.severity <= 1).slice(0, 5),
    }));
  }
}
main().catch((error) => { console.error(error); process.exit(2); });
