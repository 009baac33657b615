// Copies the browser files of the npm dependencies into web/vendor/ (git-ignored), because
// shore_server serves web/ as it is and the page must load nothing from the internet at run time.
// Runs as the npm `postinstall` step, so `npm ci` in web/ is all it takes.
import { copyFileSync, mkdirSync, readFileSync, writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const web = join(dirname(fileURLToPath(import.meta.url)), '..');
const vendor = join(web, 'vendor');
const files = [
  ['uplot/dist/uPlot.esm.js', 'uPlot.esm.js'],
  ['uplot/dist/uPlot.min.css', 'uPlot.min.css'],
  ['uplot/LICENSE', 'uPlot.LICENSE'],
];
mkdirSync(vendor, { recursive: true });
for (const [from, to] of files) copyFileSync(join(web, 'node_modules', from), join(vendor, to));
const version = JSON.parse(readFileSync(join(web, 'node_modules/uplot/package.json'), 'utf8')).version;
writeFileSync(join(vendor, 'VERSIONS'), `uplot ${version}\n`);
console.log(`vendor: uPlot ${version} -> web/vendor/`);
