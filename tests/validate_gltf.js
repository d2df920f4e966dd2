// validate_gltf.js -- run the Khronos glTF validator (npm package
// gltf-validator) on glTF / GLB files and print its findings.
//
//   node validate_gltf.js MODULE_DIR FILE...
//
// MODULE_DIR is the node_modules folder that holds gltf-validator
// (scripts/setup.sh installs it into build/npm/node_modules).  Prints one
// line per file, "FILE: N errors, N warnings, N infos, N hints", then each
// error and warning as "  severity code pointer: message".  Images a file
// names by relative URI are read from its folder.  Exit status: 0
// when no file has an error, 1 when one has, 2 when the validator cannot
// be loaded or a file read.
'use strict';
const fs = require('fs');
const path = require('path');

const [moduleDir, ...files] = process.argv.slice(2);
let validator;
try {
  validator = require(path.resolve(moduleDir, 'gltf-validator'));
} catch (e) {
  console.log(`cannot load gltf-validator from ${moduleDir}: ${e.message}`);
  process.exit(2);
}

const severities = ['error', 'warning', 'info', 'hint'];

async function main() {
  let errors = 0;
  for (const file of files) {
    const bytes = new Uint8Array(fs.readFileSync(file));
    // The files hold their buffer (GLB chunk or data URI); images (the
    // lightmaps of `radiosity bake`) are read from the file's folder.
    const report = await validator.validateBytes(bytes, {
      uri: path.basename(file),
      maxIssues: 0,
      externalResourceFunction: (uri) => new Promise((resolve, reject) => {
        const name = decodeURIComponent(uri);
        if (name.includes('/') || name.includes('..'))
          reject(new Error(`external resource ${uri} outside the file's folder`));
        else
          fs.readFile(path.join(path.dirname(file), name), (e, data) => e ? reject(e) : resolve(new Uint8Array(data)));
      }),
    });
    const i = report.issues;
    console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ` +
                `${i.numHints} hints`);
    for (const m of i.messages)
      if (m.severity <= 1)
        console.log(`  ${severities[m.severity]} ${m.code} ${m.pointer || ''}: ${m.message}`);
    errors += i.numErrors;
  }
  process.exit(errors > 0 ? 1 : 0);
}

main().catch((e) => {
  console.log(`validator failed: ${e.message}`);
  process.exit(2);
});
