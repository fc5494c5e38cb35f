// tests/browser/ktx_parse_check.mjs — ibl-bake's block-compressed KTX2 files read by ktx-parse (Don
// McCurdy's KTX 2.0 parser, used by three.js and glTF-Transform): an independent reader checks the
// header, the level index, the data format descriptor and the level lengths that
// tools/ibl-bake/io/ktx2.hpp documents. The ctest ktx_parse_compressed runs it:
//
//   node ktx_parse_check.mjs --tool IBL_BAKE --npm NPM --modules DIR [--viewer tools/viewer/ktx2.js]
//
// It bakes --size 32 --quality low --checks none --levels 6 --sheen (levels down to 1x1: below the
// block size; sheen.ktx2 too) with --ktx2-format bc6h, astc4x4, astc6x6 and bc6h with --ktx2-zstd 3
// into a temporary folder, and for every *.ktx2 each bake wrote (specular.ktx2, irradiance.ktx2,
// sheen.ktx2) checks with ktx-parse's read():
//   vkFormat 143 / 1000066000 / 1000066004, typeSize 1, pixelWidth = pixelHeight, a power of two
//   (32 for the chain), pixelDepth 0, layerCount 0, faceCount 6, levelCount in [1, log2 n + 1]
//   (the chain: report.json's stored_levels, 6: down to 1x1); supercompressionScheme 0 or 2 (Zstandard);
//   the DFD: vendorId 0, descriptorType 0, versionNumber 2, colorModel 131 (BC6H) / 162 (ASTC),
//   primaries BT709 (1), transfer LINEAR (1), flags 0, texelBlockDimension [3,3,0,0] / [5,5,0,0],
//   bytesPlane [16,0,...], one sample: bitOffset 0, bitLength 127, channelType 0x80 (BC6H: FLOAT) /
//   0xC0 (ASTC: FLOAT|SIGNED), position 0, lower 0 / 0xBF800000 (-1.0f), upper 0x3F800000 (1.0f);
//   each level's uncompressedByteLength = 6 ceil(s/b)^2 x 16 (s = max(1, n >> l)), its byteLength the
//   same without supercompression (levels 16-byte aligned), and with Zstandard the level inflated by
//   fzstd has that length and equals the same level of the plain bc6h bake byte for byte (the encoder
//   is deterministic);
//   the KTXwriter key; and that the viewer's reader (tools/viewer/ktx2.js, --viewer) finds the same
//   levels and bytes (plain files) or refuses the supercompressed one with its message.
// ktx-parse 2.0.0 and fzstd 0.1.1 are installed (pinned) with npm into --modules on the first run;
// without npm, or when the install fails (no registry), the script exits 77: skipped, said so.

import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { createRequire } from 'node:module';
import { pathToFileURL } from 'node:url';

const SKIP = 77;
const args = {};
for (let i = 2; i < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
if (!args.tool || !args.modules) {
    console.error('usage: node ktx_parse_check.mjs --tool IBL_BAKE --npm NPM --modules DIR [--viewer ktx2.js]');
    process.exit(2);
}

// ---- the packages ----------------------------------------------------------------------------------

const PACKAGES = ['ktx-parse@2.0.0', 'fzstd@0.1.1'];

async function loadPackages(dir) {
    const req = createRequire(path.join(dir, 'package.json'));
    const installed = () => {
        try {
            return PACKAGES.every((p) => {
                const [name, version] = p.split(/@(?=[^@]*$)/);
                return JSON.parse(fs.readFileSync(path.join(dir, 'node_modules', name, 'package.json'), 'utf8')).version === version;
            });
        } catch {
            return false;
        }
    };
    if (!installed()) {
        fs.mkdirSync(dir, { recursive: true });
        if (!fs.existsSync(path.join(dir, 'package.json')))
            fs.writeFileSync(path.join(dir, 'package.json'), '{"name": "ibl-ktx-parse-check", "private": true}\n');
        try {
            execFileSync(args.npm || 'npm', ['install', '--no-audit', '--no-fund', '--silent', '--prefix', dir, ...PACKAGES],
                         { stdio: ['ignore', 'pipe', 'pipe'], timeout: 180000 });
        } catch (e) {
            console.log(`SKIPPED: npm install ${PACKAGES.join(' ')} into ${dir} failed (no npm or no registry?): ` +
                        String(e.stderr || e.message).trim().split('\n').slice(-3).join(' | '));
            process.exit(SKIP);
        }
    }
    const ktx = await import(pathToFileURL(req.resolve('ktx-parse')).href);
    const fzstd = req('fzstd');
    return { ktx, fzstd };
}

// ---- expectations ---------------------------------------------------------------------------------

const FORMATS = {
    bc6h: { vk: 143, block: 4, model: 131, type: 0x80, lower: 0, upper: 0x3f800000 },
    astc4x4: { vk: 1000066000, block: 4, model: 162, type: 0xc0, lower: 0xbf800000 | 0, upper: 0x3f800000 },
    astc6x6: { vk: 1000066004, block: 6, model: 162, type: 0xc0, lower: 0xbf800000 | 0, upper: 0x3f800000 },
};

let failures = 0, checks = 0;
function expect(what, got, want) {
    ++checks;
    const same = JSON.stringify(got) === JSON.stringify(want);
    if (!same) {
        ++failures;
        console.log(`  FAIL ${what}: ${JSON.stringify(got)}, expected ${JSON.stringify(want)}`);
    }
    return same;
}

const levelBytes = (f, s) => 6 * Math.ceil(s / f.block) ** 2 * 16;

function checkFile(ktx, fzstd, file, fmtName, zstd, plainLevels, expectLevels, viewer) {
    const f = FORMATS[fmtName];
    const bytes = new Uint8Array(fs.readFileSync(file)); // a copy: byteOffset 0, offsets below are file offsets
    const c = ktx.read(bytes);
    const n = c.pixelWidth;
    const full = Math.floor(Math.log2(n)) + 1;
    expect('vkFormat', c.vkFormat, f.vk);
    expect('typeSize', c.typeSize, 1);
    expect('pixelHeight = pixelWidth', c.pixelHeight, n);
    expect('pixelWidth a power of two', Number.isInteger(Math.log2(n)), true);
    if (expectLevels.size) expect('pixelWidth', n, expectLevels.size);
    expect('pixelDepth', c.pixelDepth, 0);
    expect('layerCount', c.layerCount, 0);
    expect('faceCount', c.faceCount, 6);
    expect('levelCount in [1, log2 n + 1]', c.levelCount >= 1 && c.levelCount <= full, true);
    if (expectLevels.levels) expect('levelCount = report.json stored_levels', c.levelCount, expectLevels.levels);
    expect('supercompressionScheme', c.supercompressionScheme, zstd ? 2 : 0);
    expect('one DFD block', c.dataFormatDescriptor.length, 1);
    const d = c.dataFormatDescriptor[0];
    expect('DFD vendorId, descriptorType, versionNumber', [d.vendorId, d.descriptorType, d.versionNumber], [0, 0, 2]);
    expect('DFD colorModel', d.colorModel, f.model);
    expect('DFD colorPrimaries, transferFunction, flags', [d.colorPrimaries, d.transferFunction, d.flags], [1, 1, 0]);
    expect('DFD texelBlockDimension', d.texelBlockDimension, [f.block - 1, f.block - 1, 0, 0]);
    expect('DFD bytesPlane', d.bytesPlane, [16, 0, 0, 0, 0, 0, 0, 0]);
    expect('DFD sample count', d.samples.length, 1);
    if (d.samples.length === 1) {
        const s = d.samples[0];
        expect('DFD sample (offset, length, channelType, position)', [s.bitOffset, s.bitLength, s.channelType, s.samplePosition],
               [0, 127, f.type, [0, 0, 0, 0]]);
        expect('DFD sample lower, upper', [s.sampleLower, s.sampleUpper], [f.lower, f.upper]);
    }
    expect('KTXwriter', typeof c.keyValue.KTXwriter === 'string' && c.keyValue.KTXwriter.startsWith('ibl-bake'), true);
    const inflated = [];
    c.levels.forEach((lv, l) => {
        const s = Math.max(1, n >> l), want = levelBytes(f, s);
        expect(`level ${l} (${s}^2) uncompressedByteLength`, lv.uncompressedByteLength, want);
        if (!zstd) {
            expect(`level ${l} byteLength`, lv.levelData.byteLength, want);
            expect(`level ${l} byteOffset % 16`, lv.levelData.byteOffset % 16, 0);
            inflated.push(lv.levelData);
        } else {
            const raw = fzstd.decompress(lv.levelData);
            expect(`level ${l} inflated length`, raw.byteLength, want);
            if (plainLevels) expect(`level ${l} inflated = the plain bake's level`, Buffer.compare(Buffer.from(raw), Buffer.from(plainLevels[l])), 0);
            inflated.push(raw);
        }
    });
    // the levels lie inside the file and do not overlap
    if (!zstd) {
        const spans = c.levels.map((lv) => [lv.levelData.byteOffset, lv.levelData.byteOffset + lv.levelData.byteLength]).sort((a, b) => a[0] - b[0]);
        for (let k = 1; k < spans.length; ++k) expect(`levels ${k - 1}, ${k} disjoint`, spans[k][0] >= spans[k - 1][1], true);
        expect('last level inside the file', spans[spans.length - 1][1] <= bytes.byteLength, true);
    }
    if (viewer) {
        try {
            const v = viewer.parseKtx2Cubemap(bytes.buffer, path.basename(file));
            expect('viewer: no supercompressed file accepted', zstd, false);
            expect('viewer: format', [v.vkFormat, v.format.block], [f.vk, f.block]);
            expect('viewer: levels', v.levels.map((lv) => lv.size), c.levels.map((_, l) => Math.max(1, n >> l)));
            v.levels.forEach((lv, l) => {
                const joined = Buffer.concat(lv.faces.map((a) => Buffer.from(a.buffer, a.byteOffset, a.byteLength)));
                expect(`viewer: level ${l} bytes = ktx-parse's`, Buffer.compare(joined, Buffer.from(inflated[l])), 0);
            });
        } catch (e) {
            expect('viewer: refuses only the supercompressed file', zstd, true);
            if (zstd) expect('viewer: says --ktx2-zstd 0', /--ktx2-zstd 0/.test(e.message), true);
            else console.log(`  viewer: ${e.message}`);
        }
    }
    const sizes = c.levels.map((lv) => lv.levelData.byteLength);
    console.log(`  ${path.basename(file)}: vkFormat ${c.vkFormat}, ${n}^2 x 6, ${c.levelCount} levels, ` +
                `scheme ${c.supercompressionScheme}, ${bytes.byteLength} bytes (levels ${sizes.join('/')})`);
    return inflated;
}

// ---- main -----------------------------------------------------------------------------------------

const { ktx, fzstd } = await loadPackages(path.resolve(args.modules));
const viewer = args.viewer
    ? await import('data:text/javascript;base64,' + Buffer.from(fs.readFileSync(args.viewer)).toString('base64'))
    : null;
const work = fs.mkdtempSync(path.join(os.tmpdir(), 'ibl-ktx-parse-'));
try {
    const bakes = [
        { name: 'bc6h', format: 'bc6h', zstd: 0 },
        { name: 'astc4x4', format: 'astc4x4', zstd: 0 },
        { name: 'astc6x6', format: 'astc6x6', zstd: 0 },
        { name: 'bc6h-zstd', format: 'bc6h', zstd: 3 },
    ];
    const plain = {};
    for (const b of bakes) {
        const out = path.join(work, b.name);
        const t0 = Date.now();
        execFileSync(args.tool, ['--size', '32', '--quality', 'low', '--checks', 'none', '--levels', '6', '--sheen', '--ktx2-format', b.format,
                                 '--ktx2-zstd', String(b.zstd), '--out', out, '--quiet'], { stdio: ['ignore', 'ignore', 'inherit'] });
        console.log(`${b.name}: ibl-bake --levels 6 --sheen --ktx2-format ${b.format} --ktx2-zstd ${b.zstd} (${Date.now() - t0} ms)`);
        const report = JSON.parse(fs.readFileSync(path.join(out, 'report.json'), 'utf8'));
        const rt = report.plan.runtime;
        const files = fs.readdirSync(out).filter((f) => f.endsWith('.ktx2')).sort();
        expect(`${b.name}: specular.ktx2 written`, files.includes('specular.ktx2'), true);
        for (const file of files) {
            const want = file === 'specular.ktx2' ? { size: 32, levels: rt.stored_levels } : {};
            if (file === 'specular.ktx2') expect('specular.ktx2: report.json stored_levels = 6', rt.stored_levels, 6);
            const levels = checkFile(ktx, fzstd, path.join(out, file), b.format, b.zstd > 0,
                                     b.zstd ? plain[`${b.format}/${file}`] : null, want, viewer);
            if (!b.zstd) plain[`${b.format}/${file}`] = levels;
        }
    }
} finally {
    fs.rmSync(work, { recursive: true, force: true });
}
console.log(`${checks} checks, ${failures} failed`);
console.log(failures ? 'FAIL' : 'PASS');
process.exit(failures ? 1 : 0);
