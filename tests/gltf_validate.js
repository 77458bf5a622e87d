// Validate .glb files with the Khronos glTF validator; print one JSON report per file.
// Usage: node tests/gltf_validate.js MODULE_DIR FILE.glb...
const fs = require('fs');
const path = require('path');
const validator = require(path.join(process.argv[2], 'gltf-validator'));

async function main() {
  for (const file of process.argv.slice(3)) {
    // pictures named by relative URI (a city's shared textures/) are read beside the file:
    // one that is missing is an error
    const externalResourceFunction = (uri) => new Promise((resolve, reject) => {
      fs.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)), (error, data) =>
        error ? reject(error.toString()) : resolve(new Uint8Array(data)));
    });
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
      uri: path.basename(file), externalResourceFunction,
    });
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
