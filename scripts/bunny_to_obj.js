#!/usr/bin/env node
// Converts the Stanford bunny of the npm package `bunny` 1.0.1 (public domain; {positions, cells})
// into assets/bunny.obj, scaled by 0.01 so the model is about 10 cm long, in metres.
//   cd /tmp && npm pack bunny@1.0.1 && tar xzf bunny-1.0.1.tgz && node scripts/bunny_to_obj.js /tmp/package assets/bunny.obj
const fs = require('fs');
const [pkg, out] = process.argv.slice(2);
if (!pkg || !out) { console.error('usage: bunny_to_obj.js PACKAGE_DIR OUT.obj'); process.exit(2); }
const bunny = require(require('path').resolve(pkg, 'index.js'));
const scale = 0.01;
const lines = ['# Stanford bunny (public domain), npm package bunny 1.0.1, scaled by 0.01 to metres'];
for (const p of bunny.positions) lines.push(`v ${(p[0] * scale).toPrecision(9)} ${(p[1] * scale).toPrecision(9)} ${(p[2] * scale).toPrecision(9)}`);
for (const c of bunny.cells) lines.push(`f ${c[0] + 1} ${c[1] + 1} ${c[2] + 1}`);
fs.writeFileSync(out + '.tmp', lines.join('\n') + '\n');
fs.renameSync(out + '.tmp', out);
console.log(`wrote ${bunny.positions.length} vertices, ${bunny.cells.length} triangles to ${out}`);
