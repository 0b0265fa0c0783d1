// Validates one glTF/GLB file with the Khronos validator; prints a JSON summary.
const { validateBytes } = require('gltf-validator');
const fs = require('fs');
const data = new Uint8Array(fs.readFileSync(process.argv[2]));
validateBytes(data, { maxIssues: 100 }).then((report) => {
  const issues = report.issues;
  const errors = issues.messages.filter((m) => m.severity === 0).slice(0, 10);
  console.log(JSON.stringify({ errors: issues.numErrors, warnings: issues.numWarnings, first_errors: errors }));
}).catch((e) => { console.error(String(e)); process.exit(3); });
