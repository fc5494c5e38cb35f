// tools/viewer/viewer.js — WebGL2 viewer of an ibl-bake output folder, shaded by the library's
// GLSL (include/ibl/glsl/*.glsl). docs/shaders.md describes it.
//
// Query parameters:
//   bake=URL     the bake folder (relative to this page or absolute), e.g. ?bake=../../build/bake/
//   glsl=URL     where ibl_*.glsl live (default ../../include/ibl/glsl/)
//   test=preview render ibl-bake's preview.png exactly (640 x 256) and POST the pixels to `report`
//   test=numeric evaluate the GLSL functions on fixed inputs (numeric.frag.glsl) and POST them
//   test=prefilter filter the fixtures' sky with ibl_prefilter.glsl and POST every texel
//   test=refilter re-filter the bake's chain live (Renderer.refilter) and POST every level as
//                loaded (the C++ chain) and as re-filtered (read back from the chain texture)
//   test=bc6h    read every texel of the BC6H fixtures' blocks through EXT_texture_compression_bptc
//                and POST them (tests/browser/run_browser_test.py --mode bc6h compares them)
//   report=URL   where a test POSTs its JSON result (tests/browser/run_browser_test.py serves it)
//   roughness=, ev=, lookup=, scatter=, grid=1, light=1, ss=  the controls' initial values
// Without bake=, pick the folder with the file picker (the browser reads it locally).
//
// Files read from the folder: specular.ktx2 (required), dfg.hpp (required: the exact float table
// in the layout of report.json), report.json (plan.runtime: the lookup conventions; source: the
// exposure and camera of the preview), sh.json ("irradiance_over_pi_shader", or its "_windowed" form) or
// irradiance.ktx2 (texels hold E; used when plan.runtime.diffuse is "irradiance_map"), lights.json
// (optional: an extracted sun, added back as a disk light; the chain and the diffuse product hold the
// environment without it), lobe_lut.hpp (when plan.runtime.runtime_model.name is "lobe": the lobe
// LUT, and the spheres are shaded by the lobe model: with runtime_model.parts = 2 also
// lobe_lut_b.hpp, the B part's kernel table, and the two-part model ibl_lobe_pair_sample; a bake
// without parts: the one-kernel ibl_lobe_sample), lobe_taps.hpp (when it is
// "taps2": the two-tap table, uploaded as the two RGBA textures of ibl_common.glsl's storage split,
// and the spheres are shaded by the two-tap model, ibl_lobe_taps2_sample); else by the split
// sum.
// The KTX2 files may hold any of ibl-bake's formats: the block-compressed ones (--ktx2-format bc6h,
// astc4x4, astc6x6) are uploaded as blocks through the browser's EXT_texture_compression_bptc (BC6H)
// or WEBGL_compressed_texture_astc with the 'hdr' profile (ASTC); where the browser lacks them, and
// for Zstandard-supercompressed files (--ktx2-zstd N), the panel says so and nothing is drawn.

import { parseKtx2Cubemap, meanLuminance, halfToFloat } from './ktx2.js';
import { packSource, parseFastShapes, fastTaps, midTail, midTailDefaults, splitPeaks, makePeakLevel, shBands, shProject, shProjectionLevel, shLevel } from './refilter.js';

const params = new URLSearchParams(location.search);
const testMode = params.get('test');
const glslBase = params.get('glsl') || '../../include/ibl/glsl/';
const statusEl = document.getElementById('status');
const log = (s) => { if (statusEl) statusEl.textContent += s + '\n'; };

// ---- where the bake's files come from --------------------------------------------------------------

function urlSource(base) {
    if (!base.endsWith('/')) base += '/';
    const get = async (name) => {
        const r = await fetch(base + name);
        if (!r.ok) throw new Error(`${base + name}: HTTP ${r.status}`);
        return r;
    };
    return {
        label: base,
        has: async (name) => { try { return (await fetch(base + name, { method: 'HEAD' })).ok; } catch { return false; } },
        text: async (name) => (await get(name)).text(),
        bytes: async (name) => (await get(name)).arrayBuffer(),
    };
}

function fileSource(files) {
    const byName = new Map();
    for (const f of files) byName.set(f.name, f);
    const get = (name) => {
        const f = byName.get(name);
        if (!f) throw new Error(`${name} is not in the chosen folder`);
        return f;
    };
    return {
        label: files.length ? (files[0].webkitRelativePath || files[0].name).split('/')[0] : '(none)',
        has: async (name) => byName.has(name),
        text: async (name) => get(name).text(),
        bytes: async (name) => get(name).arrayBuffer(),
    };
}

/// The table of dfg.hpp (ibl::dfg_lut_header) or lobe_lut.hpp (name 'lobe_lut'): size, channels,
/// values row by row.
export function parseDfgHeader(text, name = 'dfg_lut') {
    const size = +(new RegExp(`${name}_size\\s*=\\s*(\\d+)`).exec(text) || [])[1];
    const channels = +(new RegExp(`${name}_channels\\s*=\\s*(\\d+)`).exec(text) || [])[1];
    const start = text.indexOf('{', text.search(new RegExp(`${name}\\s*\\[\\s*\\d+\\s*\\]\\s*=`)));
    const end = text.indexOf('}', start);
    if (!(size > 0) || !(channels > 0) || start < 0 || end < 0) throw new Error(`${name}: no ${name} table`);
    const values = text.slice(start + 1, end).split(',').map((s) => s.trim()).filter((s) => s.length).map(parseFloat);
    if (values.length !== size * size * channels || values.some((v) => !Number.isFinite(v)))
        throw new Error(`${name}: ${values.length} values, expected ${size * size * channels}`);
    return { size, channels, values: Float32Array.from(values) };
}

/// The runtime model named by report.json (plan.runtime.runtime_model.name): 'lobe', 'taps2' or
/// 'split-sum' (bakes without the entry: the split sum).
function runtimeModelOf(report) {
    const m = report && report.plan && report.plan.runtime && report.plan.runtime.runtime_model;
    return m && (m.name === 'lobe' || m.name === 'taps2') ? m.name : 'split-sum';
}

/// Channels [first, first + 4) of a table of lobe_taps.hpp: one texture of the GLSL storage split.
function tapsHalf(taps, first) {
    const n = taps.size * taps.size, values = new Float32Array(4 * n);
    for (let i = 0; i < n; ++i) for (let k = 0; k < 4; ++k) values[4 * i + k] = taps.values[taps.channels * i + first + k];
    return { size: taps.size, channels: 4, values };
}

async function loadBake(src) {
    const bake = { label: src.label };
    bake.report = (await src.has('report.json')) ? JSON.parse(await src.text('report.json')) : null;
    bake.sh = (await src.has('sh.json')) ? JSON.parse(await src.text('sh.json')) : null;
    bake.dfg = parseDfgHeader(await src.text('dfg.hpp'));
    bake.model = runtimeModelOf(bake.report);
    bake.lobe = bake.model === 'lobe' ? parseDfgHeader(await src.text('lobe_lut.hpp'), 'lobe_lut') : null;
    const parts = bake.report && bake.report.plan.runtime.runtime_model.parts;
    bake.lobeB = bake.model === 'lobe' && parts === 2 ? parseDfgHeader(await src.text('lobe_lut_b.hpp'), 'lobe_lut_b') : null;
    bake.taps = bake.model === 'taps2' ? parseDfgHeader(await src.text('lobe_taps.hpp'), 'lobe_taps') : null;
    if (bake.taps && bake.taps.channels !== 8) throw new Error(`lobe_taps.hpp: ${bake.taps.channels} channels, expected 8 (two taps)`);
    bake.chain = parseKtx2Cubemap(await src.bytes('specular.ktx2'), 'specular.ktx2');
    bake.irradiance = (await src.has('irradiance.ktx2')) ? parseKtx2Cubemap(await src.bytes('irradiance.ktx2'), 'irradiance.ktx2') : null;
    bake.sun = (await src.has('lights.json')) ? sunOf(JSON.parse(await src.text('lights.json'))) : null;
    return bake;
}

/// The first "sun" of lights.json ({"lights": [{"type": "sun", "direction", "solid_angle", "radiance", ...}]}),
/// or null. The disk light of shade.hpp: direction (unit, towards it), solid angle (sr), radiance.
export function sunOf(lights) {
    const list = (lights && Array.isArray(lights.lights)) ? lights.lights : [];
    const s = list.find((l) => l && l.type === 'sun');
    if (!s) return null;
    const vec = (a) => Array.isArray(a) && a.length === 3 && a.every(Number.isFinite);
    if (!vec(s.direction) || !vec(s.radiance) || !Number.isFinite(s.solid_angle)) throw new Error('lights.json: a sun needs direction, solid_angle, radiance');
    return { direction: s.direction, solidAngle: s.solid_angle, radiance: s.radiance };
}

// ---- conventions from report.json ------------------------------------------------------------------

const AXIS = { linear: 0, sqrt: 1, cbrt: 2 };
const WEIGHT = { lod: 0, power: 1, log: 2 };
const INTERP = { linear: 0, catmull_rom: 1, geometric: 2 };

function runtimeOf(bake) {
    const rt = (bake.report && bake.report.plan && bake.report.plan.runtime) || {};
    const stored = bake.chain.levels.length;
    const spec = rt.specular_lookup || { weight: 'log', interpolation: 'geometric', name: 'log-geometric' };
    const lay = rt.dfg_layout || { n_dot_v: 'cbrt', roughness: 'sqrt', edge_aligned: true };
    const diffuse = rt.diffuse || (bake.sh ? 'sh' : bake.irradiance ? 'irradiance_map' : 'none');
    return {
        virtualLevels: rt.virtual_levels ?? stored,
        firstLevel: rt.first_level ?? 0,
        stored,
        mapping: rt.policy === 'filament' ? 1 : 0,
        spec,
        layout: [AXIS[lay.n_dot_v] ?? 2, AXIS[lay.roughness] ?? 1, lay.edge_aligned === false ? 0 : 1],
        diffuse,
    };
}

/// The preview's camera (stage_preview.cpp make_camera): looking horizontally away from `light`.
export function previewCamera(light) {
    let f = [-light[0], 0, -light[2]];
    const l2 = f[0] * f[0] + f[2] * f[2];
    f = l2 > 1e-12 ? [f[0] / Math.sqrt(l2), 0, f[2] / Math.sqrt(l2)] : [0, 0, -1];
    const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    const norm = (a) => { const n = Math.hypot(a[0], a[1], a[2]); return [a[0] / n, a[1] / n, a[2] / n]; };
    const right = norm(cross(f, [0, 1, 0]));
    return { fwd: f, right, up: cross(right, f) };
}

// ---- GL ------------------------------------------------------------------------------------------

const VERTEX = `#version 300 es
void main() {
    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}`;
const HEADER = '#version 300 es\nprecision highp float;\nprecision highp int;\nprecision highp samplerCube;\nprecision highp sampler2D;\n';

async function fetchText(url) {
    const r = await fetch(url);
    if (!r.ok) throw new Error(`${url}: HTTP ${r.status}`);
    return r.text();
}

async function libraryGlsl() {
    const parts = [];
    for (const f of ['ibl_common.glsl', 'ibl_lookup.glsl', 'ibl_sh.glsl', 'ibl_shade.glsl', 'ibl_runtime.glsl', 'ibl_prefilter.glsl',
                     'ibl_local_probe.glsl']) parts.push(await fetchText(glslBase + f));
    return parts.join('\n');
}

function compile(gl, vsrc, fsrc) {
    const sh = (type, src) => {
        const s = gl.createShader(type);
        gl.shaderSource(s, src);
        gl.compileShader(s);
        if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error('shader: ' + gl.getShaderInfoLog(s));
        return s;
    };
    const p = gl.createProgram();
    gl.attachShader(p, sh(gl.VERTEX_SHADER, vsrc));
    gl.attachShader(p, sh(gl.FRAGMENT_SHADER, fsrc));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error('link: ' + gl.getProgramInfoLog(p));
    return p;
}

/// The WebGL extension object that uploads a block-compressed cube (ktx2.js KTX2_FORMATS: BC6H through
/// EXT_texture_compression_bptc, ASTC HDR through WEBGL_compressed_texture_astc with the 'hdr'
/// profile), or an Error that says what the browser lacks (never an upload the GPU would decode as
/// something else: an LDR-only ASTC decoder turns HDR blocks into its error colour).
export function blockExtension(gl, format, name) {
    const ext = gl.getExtension(format.extension);
    const other = 'bake with --ktx2-format rgba16f (or another format this browser offers)';
    if (!ext) return new Error(`${name} is ${format.name} (--ktx2-format ${format.option}): this browser's WebGL2 has no ` +
                               `${format.extension}; ${other}`);
    if (format.profile) {
        const profiles = ext.getSupportedProfiles ? ext.getSupportedProfiles() : [];
        if (!profiles.includes(format.profile))
            return new Error(`${name} is ${format.name} (--ktx2-format ${format.option}): this browser's ${format.extension} ` +
                             `offers the profiles [${profiles.join(', ')}], not '${format.profile}' (HDR blocks); ${other}`);
    }
    return ext;
}

/// The first of a bake's KTX2 cubes (chain, irradiance map) in a block format this browser cannot
/// upload, as blockExtension's Error; null when every cube can be uploaded.
function unsupportedBlockFormat(gl, bake) {
    for (const [name, cube] of [['specular.ktx2', bake.chain], ['irradiance.ktx2', bake.irradiance]]) {
        const e = cube && cube.format.block ? blockExtension(gl, cube.format, name) : null;
        if (e instanceof Error) return e;
    }
    return null;
}

/// A cube texture with every stored level, uploaded as stored (faces +X..-Z, rows from t = 0; the
/// block formats with compressedTexImage2D, blocks row-major from t = 0).
function uploadCube(gl, cube, name = 'the cube') {
    let ext = null;
    if (cube.format.block) {
        ext = blockExtension(gl, cube.format, name);
        if (ext instanceof Error) throw ext;
    }
    const tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, tex);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, false);
    if (cube.vkFormat === 109 && !gl.getExtension('OES_texture_float_linear'))
        throw new Error('an RGBA32F chain needs OES_texture_float_linear to be filtered');
    if (ext) {
        const internal = ext[cube.format.internal];
        cube.levels.forEach((lv, l) => {
            for (let f = 0; f < 6; ++f)
                gl.compressedTexImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + f, l, internal, lv.size, lv.size, 0, lv.faces[f]);
        });
        const err = gl.getError();
        if (err !== gl.NO_ERROR) throw new Error(`${name}: compressedTexImage2D failed (GL error 0x${err.toString(16)})`);
    } else {
        const [internal, format, type] = cube.format.gl.map((n) => gl[n]);
        cube.levels.forEach((lv, l) => {
            for (let f = 0; f < 6; ++f)
                gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + f, l, internal, lv.size, lv.size, 0, format, type, lv.faces[f]);
        });
    }
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_BASE_LEVEL, 0);
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MAX_LEVEL, cube.levels.length - 1);
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR);
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    for (const w of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T, gl.TEXTURE_WRAP_R]) gl.texParameteri(gl.TEXTURE_CUBE_MAP, w, gl.CLAMP_TO_EDGE);
    return tex;
}

/// The DFG table as RGBA32F (exact floats) when float filtering exists, else RGBA16F.
function uploadLut(gl, dfg, channelsLayout) {
    const n = dfg.size, c = dfg.channels;
    const rgba = new Float32Array(4 * n * n);
    for (let i = 0; i < n * n; ++i) {
        for (let k = 0; k < 4; ++k) rgba[4 * i + k] = k < c ? dfg.values[c * i + k] : (k === 3 ? 1 : 0);
    }
    // --preset filament stores (B, A + B, k) for mix(dfg.x, dfg.y, f0): back to the shader's (A, B).
    if (channelsLayout && channelsLayout.startsWith('B,'))
        for (let i = 0; i < n * n; ++i) {
            const b = rgba[4 * i], e = rgba[4 * i + 1];
            rgba[4 * i] = Math.fround(e - b);
            rgba[4 * i + 1] = b;
        }
    const floatLinear = !!gl.getExtension('OES_texture_float_linear');
    const tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    gl.texImage2D(gl.TEXTURE_2D, 0, floatLinear ? gl.RGBA32F : gl.RGBA16F, n, n, 0, gl.RGBA, gl.FLOAT, rgba);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    return { tex, format: floatLinear ? 'RGBA32F' : 'RGBA16F' };
}

/// An RGBA32F 2-D texture on texture unit `unit`, read by texelFetch (nearest).
function floatTexture(gl, unit, w, h, values) {
    const t = gl.createTexture();
    gl.activeTexture(gl.TEXTURE0 + unit);
    gl.bindTexture(gl.TEXTURE_2D, t);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, w, h, 0, gl.RGBA, gl.FLOAT, values);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    return t;
}

/// The packed source (refilter.js packSource, or the C++ packing) as the RGBA32F texture
/// ibl_prefilter.glsl reads on unit 0, `width` texels per row.
function packedTexture(gl, data, width, unit = 0) {
    const height = Math.ceil(data.length / 4 / width), all = new Float32Array(4 * width * height);
    all.set(data);
    return floatTexture(gl, unit, width, height, all);
}

/// The passes of ibl_prefilter.glsl, one per face of each level: the packed source bound on unit 0;
/// per level { n, count, factor, taps, info } its taps uploaded on unit 1 and, with { peak_count,
/// peaks (px, py, pz, er, eg, eb per peak), a2, g1 } (the peak split, make_peak_level),
/// its peaks on unit 3 (a 1 x 2 zero texture without), and with { tail_share > 0, next } the coarse
/// tail: next() (called when the level's turn comes, after the earlier levels' done) returns
/// { n, data } the next level before its peaks (the shader's second output) packed with its border
/// (refilter.js packSource(n, rgbOf, null, 1)), uploaded on unit 4, and with { sh_bands > 0, sh }
/// (refilter.js shLevel: sh_pair_count x 3 texels) the level reconstructed from its spherical
/// harmonics instead of its taps, the texture on unit 6. target(level, face) binds the
/// framebuffer's attachments before a pass (the second, when bound, receives the texel before its
/// peaks), done(level, face) runs after it. Returns the textures it made (the caller deletes them).
function prefilterPasses(gl, program, vao, levels, target, done = () => {}) {
    const u = (name) => gl.getUniformLocation(program, name);
    gl.useProgram(program);
    gl.bindVertexArray(vao);
    gl.uniform1i(u('u_src'), 0);
    gl.uniform1i(u('u_taps'), 1);
    gl.uniform1i(u('u_peaks'), 3);
    gl.uniform1i(u('u_next'), 4);
    gl.uniform1i(u('u_sh'), 6);
    const made = [];
    for (const lv of levels) {
        const share = lv.tail_share > 0 ? lv.tail_share : 0;
        const next = share > 0 ? lv.next() : { n: 1, data: new Float32Array(8) };
        made.push(packedTexture(gl, next.data, 256, 4));
        gl.uniform1i(u('u_next_n'), next.n);
        gl.uniform1f(u('u_tail_share'), share);
        const width = Math.max(1, lv.count), both = new Float32Array(8 * width); // a level by SH may have no taps
        both.set(lv.taps);
        both.set(lv.info, 4 * width);
        made.push(floatTexture(gl, 1, width, 2, both));
        const np = lv.peak_count || 0, peaks = new Float32Array(8 * Math.max(1, np));
        for (let j = 0; j < np; ++j)
            for (let c = 0; c < 3; ++c) {
                peaks[4 * j + c] = lv.peaks[6 * j + c];
                peaks[4 * (np + j) + c] = lv.peaks[6 * j + 3 + c];
            }
        made.push(floatTexture(gl, 3, Math.max(1, np), 2, peaks));
        gl.uniform1i(u('u_peak_count'), np);
        gl.uniform1f(u('u_peak_a2'), np ? lv.a2 : 0);
        gl.uniform1i(u('u_peak_g1'), np && lv.g1 ? 1 : 0);
        const bands = lv.sh_bands > 0 ? lv.sh_bands : 0;
        if (bands > 0 && lv.sh.length !== 12 * (bands * (bands + 1) / 2)) throw new Error(`level ${lv.level}: sh texture of the wrong size`);
        made.push(bands > 0 ? floatTexture(gl, 6, bands * (bands + 1) / 2, 3, Float32Array.from(lv.sh)) : floatTexture(gl, 6, 1, 3, new Float32Array(12)));
        gl.uniform1i(u('u_sh_bands'), bands);
        gl.uniform1i(u('u_count'), lv.count);
        gl.uniform1f(u('u_factor'), lv.factor);
        gl.uniform1i(u('u_n'), lv.n);
        gl.viewport(0, 0, lv.n, lv.n);
        for (let f = 0; f < 6; ++f) {
            target(lv, f);
            gl.uniform1i(u('u_face'), f);
            gl.drawArrays(gl.TRIANGLES, 0, 3);
            done(lv, f);
        }
    }
    return made;
}

/// The projection of the packed source onto `bands` bands on the GPU (sh_project.frag.glsl,
/// ibl_prefilter_sh_project), from the texture on unit 0 holding `packed` (refilter.js packSource,
/// `width` texels a row): the level refilter.js shProject projects, one pass of sh_pair_count x 12
/// texels, read back and summed over the faces in double. Returns what shProject returns ({ bands,
/// face, coef, unit }, 6 per pair), for refilter.js shLevel.
function gpuShProject(gl, program, vao, packed, bands) {
    const lv = shProjectionLevel(packed, bands), pairs = (bands * (bands + 1)) / 2;
    gl.useProgram(program);
    gl.bindVertexArray(vao);
    gl.uniform1i(gl.getUniformLocation(program, 'u_src'), 0);
    gl.uniform4i(gl.getUniformLocation(program, 'u_level'), lv.n, lv.stride, lv.faceStride, lv.offset);
    gl.uniform1i(gl.getUniformLocation(program, 'u_bands'), bands);
    const fb = gl.createFramebuffer(), tex = gl.createTexture();
    gl.activeTexture(gl.TEXTURE7); // on no sampler's unit
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, pairs, 12, 0, gl.RGBA, gl.FLOAT, null);
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
    gl.drawBuffers([gl.COLOR_ATTACHMENT0]);
    gl.viewport(0, 0, pairs, 12);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    const px = new Float32Array(4 * pairs * 12);
    gl.readBuffer(gl.COLOR_ATTACHMENT0);
    gl.readPixels(0, 0, pairs, 12, gl.RGBA, gl.FLOAT, px);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.deleteFramebuffer(fb);
    gl.deleteTexture(tex);
    const coef = new Float64Array(6 * pairs), unit = new Float64Array(6 * pairs);
    for (let f = 0; f < 6; ++f)
        for (let p = 0; p < pairs; ++p)
            for (let half = 0; half < 2; ++half) {
                const at = 4 * ((2 * f + half) * pairs + p);
                for (let c = 0; c < 3; ++c) coef[6 * p + 3 * half + c] += px[at + c];
                for (let c = 0; c < 3; ++c) unit[6 * p + 3 * half + c] += px[at + 3];
            }
    return { bands, face: lv.n, coef, unit };
}

class Renderer {
    constructor(canvas, glsl, fragment) {
        const gl = canvas.getContext('webgl2', { antialias: false, preserveDrawingBuffer: true, alpha: false, premultipliedAlpha: false });
        if (!gl) throw new Error('WebGL2 is not available');
        this.gl = gl;
        this.canvas = canvas;
        this.program = compile(gl, VERTEX, HEADER + glsl + '\n' + fragment);
        this.glsl = glsl;
        this.vao = gl.createVertexArray();
        this.u = (name) => gl.getUniformLocation(this.program, name);
    }

    setBake(bake) {
        const gl = this.gl;
        // A block format the browser cannot upload: refuse before anything changes (the loaded bake stays).
        const unsupported = unsupportedBlockFormat(gl, bake);
        if (unsupported) throw unsupported;
        this.bake = bake;
        this.rt = runtimeOf(bake);
        this.chainTex = uploadCube(gl, bake.chain, 'specular.ktx2');
        const rtj = bake.report && bake.report.plan && bake.report.plan.runtime;
        const lut = uploadLut(gl, bake.dfg, rtj && rtj.dfg_channels_layout);
        this.lutTex = lut.tex;
        this.lutFormat = lut.format;
        this.irrTex = bake.irradiance ? uploadCube(gl, bake.irradiance, 'irradiance.ktx2') : this.chainTex;
        const lobe = bake.lobe ? uploadLut(gl, bake.lobe, null) : null; // (A, B, s, r_eff): four channels as stored
        this.lobeTex = lobe ? lobe.tex : this.lutTex;
        this.lobeFormat = lobe ? lobe.format : null;
        const lobeB = bake.lobeB ? uploadLut(gl, bake.lobeB, null) : null; // (f_B, r_B, 0, 0)
        this.lobeBTex = lobeB ? lobeB.tex : this.lutTex;
        // the two-tap table: taps_a = channels 0..3, taps_b = channels 4..7 (ibl_common.glsl)
        const tapsA = bake.taps ? uploadLut(gl, tapsHalf(bake.taps, 0), null) : null;
        const tapsB = bake.taps ? uploadLut(gl, tapsHalf(bake.taps, 4), null) : null;
        this.tapsATex = tapsA ? tapsA.tex : this.lutTex;
        this.tapsBTex = tapsB ? tapsB.tex : this.lutTex;
        this.tapsFormat = tapsA ? tapsA.format : null;
        // The renderer's coefficients: the windowed ones when sh.json has them ("radiance" is raw).
        const shc = !bake.sh ? [] : bake.sh.irradiance_over_pi_shader_windowed || bake.sh.irradiance_over_pi_shader || [];
        this.sh = new Float32Array(27);
        for (let k = 0; k < Math.min(9, shc.length); ++k) for (let ch = 0; ch < 3; ++ch) this.sh[3 * k + ch] = shc[k][ch];
        const src = bake.report && bake.report.source;
        const mean = src && Number.isFinite(src.mean_luminance) ? src.mean_luminance : meanLuminance(bake.chain, 0) || 1;
        // stage_preview.cpp: exposure = float(0.6 / max(mean, 1e-6)).
        this.exposure = Math.fround(0.6 / Math.max(mean, 1e-6));
        this.light = src && src.brightest_direction ? src.brightest_direction : [0, 1, 0];
        // ibl-bake's preview_ss: 2 x 2 at --quality low, 4 x 4 otherwise.
        const quality = bake.report && bake.report.options && bake.report.options.quality;
        this.previewSs = quality === 'low' ? 2 : 4;
    }

    /// Re-filters the loaded chain's levels >= 1 from its level 0 on the GPU with the fast filter
    /// (ibl_prefilter.glsl: refilter.js splits level 0's peaks off as the C++ prefilter does with its
    /// default peak_split_options, packs the split's base with its mips and builds each level's taps
    /// at the level's roughness from report.json, the bake's samples and reads when it was filtered
    /// by the fast filter, else the fast filter's default plan (64 x 4^(v - 1) samples at virtual
    /// level v, nearest-level reads), the chain's LD weight, its merged peaks and its coarse tail, or, for a level
    /// whose kernel needs at most 24 bands, its spherical-harmonic reconstruction from the source's
    /// projection, itself a GPU pass: sh_project.frag.glsl) and renders
    /// every face of every level into the chain texture, coarse to fine (a level's coarse tail reads
    /// the next level back from the GPU and packs it, or the intermediate level the C++ filters for
    /// it: refilter.js midTail, off where report.json's specular.mid_tail says the bake had it off).
    /// Returns { prepare_ms (split, packing, taps and peaks, CPU), gpu_ms (the passes, to gl.finish),
    /// levels, intermediate (intermediate levels drawn), peaks (level-0 peaks) }.
    refilter(prefilterFragment, shapesText, projectFragment) {
        const gl = this.gl, bake = this.bake, chain = bake.chain;
        const spec = bake.report && bake.report.specular;
        if (!spec || !Array.isArray(spec.levels)) throw new Error('re-filtering needs report.json (the levels\' roughness)');
        if (chain.vkFormat !== 97 && chain.vkFormat !== 109) throw new Error('re-filtering needs an rgba16f or rgba32f chain (--ktx2-format)');
        if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('re-filtering needs EXT_color_buffer_float');
        if (!this.prefilterProgram) this.prefilterProgram = compile(gl, VERTEX, HEADER + this.glsl + '\n' + prefilterFragment);
        if (!this.shProjectProgram) this.shProjectProgram = compile(gl, VERTEX, HEADER + this.glsl + '\n' + projectFragment);
        const t0 = performance.now();
        const l0 = chain.levels[0], n0 = l0.size, half = chain.vkFormat === 97;
        const rgbOf = (f, x, y) => {
            const a = l0.faces[f], i = 4 * (y * n0 + x);
            return half ? [halfToFloat(a[i]), halfToFloat(a[i + 1]), halfToFloat(a[i + 2])] : [a[i], a[i + 1], a[i + 2]];
        };
        const split = splitPeaks(n0, rgbOf); // the peak split with the C++ prefilter's defaults
        const packed = packSource(n0, rgbOf, split.peaks);
        const shapes = parseFastShapes(shapesText);
        const weight = spec.ld_weight === 'g1' ? 'g1' : 'nl';
        const plan = [];
        const convolved = (k) => k > 0 && k < chain.levels.length && spec.levels[k] && spec.levels[k].virtual_level > 0;
        const midOn = !(spec.mid_tail && spec.mid_tail.enabled === false);
        // The rough levels by spherical harmonics (sh_rough_options' defaults): the bands each level
        // needs, and the split's base projected once onto the most of them.
        const bands = spec.levels.map((lv, k) => (convolved(k) ? shBands(lv.roughness, weight) : 0));
        const most = Math.max(0, ...bands);
        spec.levels.forEach((lv, k) => {
            if (!convolved(k)) return;
            const peaks = makePeakLevel(split.peaks, n0, packed.levels.length, lv.roughness, weight);
            if (bands[k] > 0) { // no taps and no coarse tail
                plan.push({ k, key: `${k}`, order: k, n: chain.levels[k].size, count: 0, taps: new Float32Array(0), info: new Float32Array(0), factor: 0,
                            tail_share: 0, roughness: lv.roughness, sh_bands: bands[k], sh: null, ...peaks });
                return;
            }
            // The bake's own samples and reads when it was filtered by the fast filter, else the fast
            // filter's defaults (prefilter_plan: fast_default_samples = 64 at level 1, four times as
            // many per coarser level up to 16384, nearest-level reads).
            const fast = spec.prefilter === 'fast' && lv.samples > 0;
            let samples = 64;
            for (let v = 1; v < lv.virtual_level && samples < 16384; ++v) samples *= 4;
            if (fast) samples = lv.samples;
            const trilinear = fast ? lv.trilinear === true : false;
            // The coarse tail (prefilter_options::coarse_tail): from the next level when its face is >= 16,
            // or from an intermediate level (prefilter_options::mid_tail, refilter.js midTail: a
            // 256^2 chain's level 1) rendered just before the level, on the next level's face, with
            // its own tail from the next level and no peaks; off where the bake turned it off.
            const rn = convolved(k + 1) && chain.levels[k + 1].size >= 16 ? spec.levels[k + 1].roughness : -1;
            const s = Math.min(samples, 16384);
            const mt = midOn && rn >= 0 ? midTail(lv.roughness, rn, s, chain.levels[k + 1].size) : null;
            const key = `${k}`, nextKey = mt ? `mid${k}` : `${k + 1}`;
            if (mt)
                plan.push({ k, key: nextKey, order: k + 0.5, nextKey: `${k + 1}`, isMid: true, n: chain.levels[k + 1].size,
                            ...fastTaps(shapes, mt.roughness, mt.mid, weight, trilinear, packed, rn), peak_count: 0 });
            plan.push({ k, key, order: k, nextKey, n: chain.levels[k].size,
                        ...fastTaps(shapes, lv.roughness, mt ? mt.own : s, weight, trilinear, packed, mt ? mt.roughness : rn), ...peaks });
        });
        plan.sort((a, b) => b.order - a.order); // coarse to fine: a coarse tail reads the finished next level
        const done = new Map(); // level key -> { n, faces before their peaks (RGBA floats) }, for the level that reads it
        for (const lv of plan)
            lv.next = () => {
                const { n: m, faces } = done.get(lv.nextKey);
                return { n: m, data: packSource(m, (f, x, y) => { const i = 4 * (y * m + x); return [faces[f][i], faces[f][i + 1], faces[f][i + 2]]; }, null, 1).data };
            };
        const t1 = performance.now();
        const srcTex = packedTexture(gl, packed.data, 4096);
        if (most > 0) { // the projection on the GPU (ibl_prefilter_sh_project), then each SH level's texture
            const proj = gpuShProject(gl, this.shProjectProgram, this.vao, packed, most);
            for (const lv of plan) if (lv.sh_bands > 0) Object.assign(lv, shLevel(proj, lv.roughness, weight, lv.sh_bands));
        }
        const fb = gl.createFramebuffer();
        gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
        // An intermediate level draws only its second output (it has no peaks: both are the same).
        const needed = (lv) => lv.isMid || plan.some((p) => p.tail_share > 0 && p.nextKey === lv.key);
        let beforeTex = null; // the second output (the texels before their peaks) of a level that is read back
        const made = prefilterPasses(gl, this.prefilterProgram, this.vao, plan, (lv, f) => {
            if (lv.isMid) gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, null, 0);
            else gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_CUBE_MAP_POSITIVE_X + f, this.chainTex, lv.k);
            if (f === 0 && needed(lv)) {
                gl.activeTexture(gl.TEXTURE5); // on no sampler's unit
                if (beforeTex) gl.deleteTexture(beforeTex);
                beforeTex = gl.createTexture();
                gl.bindTexture(gl.TEXTURE_2D, beforeTex);
                gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, lv.n, lv.n, 0, gl.RGBA, gl.FLOAT, null);
                gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT1, gl.TEXTURE_2D, beforeTex, 0);
            }
            // A level that is not read back has no second attachment: one of another level's size
            // would leave the framebuffer incomplete and the pass would draw nothing.
            if (f === 0 && !needed(lv)) gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT1, gl.TEXTURE_2D, null, 0);
            const status = gl.checkFramebufferStatus(gl.FRAMEBUFFER);
            if (status !== gl.FRAMEBUFFER_COMPLETE) throw new Error(`re-filter: level ${lv.k} face ${f}: framebuffer incomplete (0x${status.toString(16)})`);
            gl.drawBuffers(lv.isMid ? [gl.NONE, gl.COLOR_ATTACHMENT1]
                                    : needed(lv) ? [gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1] : [gl.COLOR_ATTACHMENT0, gl.NONE]);
        }, (lv, f) => {
            if (!needed(lv)) return;
            const px = new Float32Array(4 * lv.n * lv.n);
            gl.readBuffer(gl.COLOR_ATTACHMENT1);
            gl.readPixels(0, 0, lv.n, lv.n, gl.RGBA, gl.FLOAT, px);
            gl.readBuffer(gl.COLOR_ATTACHMENT0);
            if (!done.has(lv.key)) done.set(lv.key, { n: lv.n, faces: [] });
            done.get(lv.key).faces[f] = px;
        });
        if (beforeTex) gl.deleteTexture(beforeTex);
        gl.finish();
        const t2 = performance.now();
        gl.bindFramebuffer(gl.FRAMEBUFFER, null);
        gl.deleteFramebuffer(fb);
        for (const t of made.concat([srcTex])) gl.deleteTexture(t);
        return { prepare_ms: t1 - t0, gpu_ms: t2 - t1, levels: plan.filter((p) => !p.isMid).length,
                 intermediate: plan.filter((p) => p.isMid).length, peaks: split.peaks.length };
    }

    /// Draws into the canvas at its current size. view: { mode, roughness, ev, lookup, multiscatter,
    /// light, ss, yaw, pitch }.
    draw(view) {
        const gl = this.gl, rt = this.rt, u = this.u;
        const w = this.canvas.width, h = this.canvas.height;
        gl.viewport(0, 0, w, h);
        gl.useProgram(this.program);
        gl.bindVertexArray(this.vao);
        gl.activeTexture(gl.TEXTURE0);
        gl.bindTexture(gl.TEXTURE_CUBE_MAP, this.chainTex);
        gl.activeTexture(gl.TEXTURE1);
        gl.bindTexture(gl.TEXTURE_2D, this.lutTex);
        gl.activeTexture(gl.TEXTURE2);
        gl.bindTexture(gl.TEXTURE_CUBE_MAP, this.irrTex);
        gl.uniform1i(u('u_chain'), 0);
        gl.uniform1i(u('u_lut'), 1);
        gl.uniform1i(u('u_irradiance'), 2);
        gl.activeTexture(gl.TEXTURE3);
        gl.bindTexture(gl.TEXTURE_2D, this.lobeTex);
        gl.uniform1i(u('u_lobe'), 3);
        gl.activeTexture(gl.TEXTURE4);
        gl.bindTexture(gl.TEXTURE_2D, this.tapsATex);
        gl.uniform1i(u('u_taps_a'), 4);
        gl.activeTexture(gl.TEXTURE5);
        gl.bindTexture(gl.TEXTURE_2D, this.tapsBTex);
        gl.uniform1i(u('u_taps_b'), 5);
        gl.activeTexture(gl.TEXTURE6);
        gl.bindTexture(gl.TEXTURE_2D, this.lobeBTex);
        gl.uniform1i(u('u_lobe_b'), 6);
        gl.uniform1i(u('u_runtime'), this.bake.model === 'lobe' ? (this.bake.lobeB ? 3 : 1) : this.bake.model === 'taps2' ? 2 : 0);
        gl.uniform3fv(u('u_sh[0]'), this.sh);
        gl.uniform1i(u('u_diffuse'), rt.diffuse === 'sh' ? 1 : rt.diffuse === 'irradiance_map' && this.bake.irradiance ? 2 : 0);
        const spec = view.lookup === 'textbook' ? { weight: 'lod', interpolation: 'linear' }
                   : view.lookup === 'log-geometric' ? { weight: 'log', interpolation: 'geometric' } : rt.spec;
        gl.uniform4i(u('u_spec_levels'), rt.virtualLevels, rt.firstLevel, rt.stored, rt.mapping);
        gl.uniform3i(u('u_spec_rule'), WEIGHT[spec.weight] ?? 2, INTERP[spec.interpolation] ?? 2, view.multiscatter === false ? 0 : 1);
        gl.uniform1f(u('u_spec_exponent'), spec.weight_exponent ?? 2.0);
        gl.uniform3i(u('u_dfg_layout'), ...rt.layout);
        gl.uniform2f(u('u_size'), w, h);
        gl.uniform1f(u('u_exposure'), this.exposure * Math.pow(2, view.ev || 0));
        gl.uniform1i(u('u_mode'), view.mode);
        gl.uniform1f(u('u_roughness'), view.roughness ?? 0.25);
        let cam, eye = [0, 0, 0], offset = [1.15, 0, 0], tanHalf;
        if (view.mode === 0) {
            cam = previewCamera(this.light);
            tanHalf = Math.tan(0.5 * 90 * Math.PI / 180);
            gl.uniform1i(u('u_ss'), this.previewSs);
        } else {
            const base = previewCamera(this.light);
            const yaw0 = Math.atan2(base.fwd[0], -base.fwd[2]);
            const yaw = yaw0 + (view.yaw || 0), pitch = view.pitch || 0;
            const fwd = [Math.sin(yaw) * Math.cos(pitch), Math.sin(pitch), -Math.cos(yaw) * Math.cos(pitch)];
            const right = [Math.cos(yaw), 0, Math.sin(yaw)];
            const up = [right[1] * fwd[2] - right[2] * fwd[1], right[2] * fwd[0] - right[0] * fwd[2], right[0] * fwd[1] - right[1] * fwd[0]];
            cam = { fwd, right, up };
            eye = fwd.map((x) => -5.5 * x);
            offset = base.right.map((x) => 1.15 * x);
            tanHalf = Math.tan(0.5 * 60 * Math.PI / 180);
            gl.uniform1i(u('u_ss'), view.ss || 1);
        }
        gl.uniform3fv(u('u_fwd'), cam.fwd);
        gl.uniform3fv(u('u_right'), cam.right);
        gl.uniform3fv(u('u_up'), cam.up);
        gl.uniform3fv(u('u_eye'), eye);
        gl.uniform3fv(u('u_sphere_offset'), offset);
        gl.uniform1f(u('u_tan_half_fov'), tanHalf);
        gl.uniform3fv(u('u_light_dir'), this.light);
        // The optional light: irradiance pi x the mean radiance (a light as bright as the whole sky).
        const e = view.light ? Math.PI / this.exposure * 0.6 : 0;
        gl.uniform3f(u('u_light_irradiance'), e, e, e);
        const sun = this.bake.sun;
        gl.uniform1i(u('u_sun_on'), sun ? 1 : 0);
        gl.uniform3fv(u('u_sun_dir'), sun ? sun.direction : [0, 1, 0]);
        gl.uniform1f(u('u_sun_solid_angle'), sun ? sun.solidAngle : 0);
        gl.uniform3fv(u('u_sun_radiance'), sun ? sun.radiance : [0, 0, 0]);
        gl.drawArrays(gl.TRIANGLES, 0, 3);
    }

    /// The canvas as RGB bytes, top row first.
    readRgb() {
        const gl = this.gl, w = this.canvas.width, h = this.canvas.height;
        const px = new Uint8Array(4 * w * h);
        gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
        const rgb = new Uint8Array(3 * w * h);
        for (let y = 0; y < h; ++y)
            for (let x = 0; x < w; ++x)
                for (let c = 0; c < 3; ++c) rgb[3 * (y * w + x) + c] = px[4 * ((h - 1 - y) * w + x) + c];
        return rgb;
    }

    info() {
        const gl = this.gl;
        return {
            renderer: rendererName(gl),
            version: gl.getParameter(gl.VERSION),
            chain_format: this.bake.chain.format.name,
            chain_levels: this.bake.chain.levels.map((l) => l.size),
            irradiance_format: this.bake.irradiance ? this.bake.irradiance.format.name : null,
            sun: this.bake.sun,
            lut_texture: this.lutFormat,
            runtime_model: this.bake.model,
            lobe_texture: this.lobeFormat,
            lobe_size: this.bake.lobe ? this.bake.lobe.size : 0,
            lobe_parts: this.bake.lobeB ? 2 : this.bake.lobe ? 1 : 0,
            taps_texture: this.tapsFormat,
            taps_size: this.bake.taps ? this.bake.taps.size : 0,
            lut_size: this.bake.dfg.size,
            exposure: this.exposure,
            preview_ss: this.previewSs,
            runtime: this.rt,
        };
    }
}

/// The GL renderer's name, unmasked where the browser allows it (e.g. "SwiftShader ...").
function rendererName(gl) {
    const ext = gl.getExtension('WEBGL_debug_renderer_info');
    return ext ? gl.getParameter(ext.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
}

function toBase64(bytes) {
    let s = '';
    for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
    return btoa(s);
}

async function post(result) {
    const url = params.get('report');
    if (!url) return;
    await fetch(url, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(result) });
}

// ---- test modes ------------------------------------------------------------------------------------

async function runPreviewTest() {
    const bake = await loadBake(urlSource(params.get('bake')));
    const canvas = document.getElementById('view');
    canvas.width = 640;
    canvas.height = 256;
    const r = new Renderer(canvas, await libraryGlsl(), await fetchText('viewer.frag.glsl'));
    // a block format this browser cannot upload: skipped, with the reason (the driver exits 77)
    const unsupported = unsupportedBlockFormat(r.gl, bake);
    if (unsupported) {
        await post({ kind: 'skip', reason: unsupported.message, renderer: rendererName(r.gl), extensions: r.gl.getSupportedExtensions() });
        return;
    }
    r.setBake(bake);
    r.draw({ mode: 0 });
    r.gl.finish();
    await post({ kind: 'preview', width: 640, height: 256, rgb: toBase64(r.readRgb()), info: r.info() });
}

async function runNumericTest() {
    const canvas = document.getElementById('view');
    const gl = canvas.getContext('webgl2');
    if (!gl) throw new Error('WebGL2 is not available');
    if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('EXT_color_buffer_float is needed to read float results');
    const program = compile(gl, VERTEX, HEADER + (await libraryGlsl()) + '\n' + (await fetchText('numeric.frag.glsl')));
    const W = 64, H = 34;
    // The runtime rows' fixtures (glsl_reference --fixtures): an RGBA32F chain, two RGBA32F tables,
    // an R32F 3-D occlusion table.
    if (!gl.getExtension('OES_texture_float_linear')) throw new Error('OES_texture_float_linear is needed to filter the fixtures');
    const fx = JSON.parse(await fetchText(params.get('bake') + 'numeric_fixtures.json'));
    const chain = gl.createTexture();
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, chain);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    fx.chain.forEach((lv, l) => {
        for (let f = 0; f < 6; ++f) {
            const rgba = new Float32Array(4 * lv.size * lv.size);
            for (let k = 0; k < lv.size * lv.size; ++k) {
                for (let c = 0; c < 3; ++c) rgba[4 * k + c] = lv.faces[f][3 * k + c];
                rgba[4 * k + 3] = 1;
            }
            gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + f, l, gl.RGBA32F, lv.size, lv.size, 0, gl.RGBA, gl.FLOAT, rgba);
        }
    });
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_BASE_LEVEL, 0);
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MAX_LEVEL, fx.chain.length - 1);
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR);
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    for (const w of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T, gl.TEXTURE_WRAP_R]) gl.texParameteri(gl.TEXTURE_CUBE_MAP, w, gl.CLAMP_TO_EDGE);
    const table = (unit, values) => {
        const t = gl.createTexture();
        gl.activeTexture(gl.TEXTURE0 + unit);
        gl.bindTexture(gl.TEXTURE_2D, t);
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, fx.taps.size, fx.taps.size, 0, gl.RGBA, gl.FLOAT, new Float32Array(values));
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    };
    table(1, fx.taps.a);
    table(2, fx.taps.b);
    // The occlusion rows' table: size^3 R32F, x = n.v, y = r, z = ao, linear, clamp to edge.
    gl.activeTexture(gl.TEXTURE3);
    gl.bindTexture(gl.TEXTURE_3D, gl.createTexture());
    gl.texImage3D(gl.TEXTURE_3D, 0, gl.R32F, fx.so.size, fx.so.size, fx.so.size, 0, gl.RED, gl.FLOAT, new Float32Array(fx.so.data));
    gl.texParameteri(gl.TEXTURE_3D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_3D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    for (const w of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T, gl.TEXTURE_WRAP_R]) gl.texParameteri(gl.TEXTURE_3D, w, gl.CLAMP_TO_EDGE);
    gl.activeTexture(gl.TEXTURE4); // the render target below binds here, on no sampler's unit
    const fb = gl.createFramebuffer(), tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, W, H, 0, gl.RGBA, gl.FLOAT, null);
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
    gl.viewport(0, 0, W, H);
    gl.useProgram(program);
    gl.uniform1i(gl.getUniformLocation(program, 'u_chain'), 0);
    gl.uniform1i(gl.getUniformLocation(program, 'u_taps_a'), 1);
    gl.uniform1i(gl.getUniformLocation(program, 'u_taps_b'), 2);
    gl.uniform1i(gl.getUniformLocation(program, 'u_so'), 3);
    gl.bindVertexArray(gl.createVertexArray());
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    const out = new Float32Array(4 * W * H);
    gl.readPixels(0, 0, W, H, gl.RGBA, gl.FLOAT, out);
    await post({ kind: 'numeric', width: W, height: H, values: Array.from(out), renderer: rendererName(gl) });
}

/// The prefilter test: the fast filter's chain of the fixtures (glsl_reference --prefilter-fixtures)
/// rendered by ibl_prefilter.glsl, one pass per face and level into an RGBA32F target; the texels
/// are posted in the chain's order (level, face, row, column).
async function runPrefilterTest() {
    const canvas = document.getElementById('view');
    const gl = canvas.getContext('webgl2');
    if (!gl) throw new Error('WebGL2 is not available');
    if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('EXT_color_buffer_float is needed to render float results');
    const program = compile(gl, VERTEX, HEADER + (await libraryGlsl()) + '\n' + (await fetchText('prefilter.frag.glsl')));
    const fx = JSON.parse(await fetchText(params.get('bake') + 'prefilter_fixtures.json'));
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    const vao = gl.createVertexArray();
    // The viewer's own inputs (refilter.js) for the same source: the peak split of the source's
    // level 0, the split's base packed, the taps from the level's roughness, samples and weight,
    // and each level's peaks.
    const n0 = fx.size;
    const srcOf = (f, x, y) => {
        const k = 3 * ((f * n0 + y) * n0 + x);
        return [fx.source[k], fx.source[k + 1], fx.source[k + 2]];
    };
    const split = splitPeaks(n0, srcOf);
    const js = packSource(n0, srcOf, split.peaks);
    // Relative to the larger of the base's and the source's texel: where a peak was taken out of a
    // mip the C++ subtracts it from its float mip of the source, whose rounding the difference keeps.
    const whole = split.peaks.length ? packSource(n0, srcOf) : js;
    let packedDiff = 0, packedDiffBase = 0;
    for (let k = 0; k < js.data.length; ++k) {
        if (k % 4 === 3) continue;
        const d = Math.abs(js.data[k] - fx.packed[k]);
        packedDiff = Math.max(packedDiff, d / Math.max(1e-30, Math.abs(fx.packed[k]), Math.abs(whole.data[k])));
        packedDiffBase = Math.max(packedDiffBase, d / Math.max(1e-30, Math.abs(fx.packed[k])));
    }
    const shapes = parseFastShapes(await fetchText(glslBase + '../bake/prefilter_fast_tables.hpp'));
    // A level with a coarse tail (tail_share > 0) has the roughness its tail reads in the fixtures:
    // the next level's, or with an intermediate level (lv.mid, whose own tail reads the next level)
    // the intermediate one's. The viewer's rule (refilter.js midTail, with the fixtures' forced
    // min_texels = 0) must find the same intermediate level, own samples and intermediate samples.
    const nextR = (lv) => (lv.mid ? lv.mid.next_roughness : lv.tail_share > 0 ? lv.next_roughness : -1);
    const jsMid = fx.levels.map((lv) => midTail(lv.roughness, nextR(lv), lv.plan_samples, lv.mid ? lv.mid.n : lv.next_n,
                                                 { ...midTailDefaults, minTexels: 0 }));
    const midDiff = fx.levels.map((lv, i) => {
        const m = jsMid[i];
        if (!m || !lv.mid) return { mid: !!m, expected_mid: !!lv.mid };
        return { mid: true, expected_mid: true, roughness_abs: Math.abs(m.roughness - lv.mid.roughness), own: m.own,
                 expected_own: lv.samples, samples: m.mid, expected_samples: lv.mid.samples };
    });
    const jsTaps = fx.levels.map((lv, i) => {
        const m = jsMid[i];
        const t = fastTaps(shapes, lv.roughness, m ? m.own : lv.plan_samples, lv.weight, lv.trilinear, js, m ? m.roughness : nextR(lv));
        if (m) t.mid = { n: lv.mid ? lv.mid.n : lv.next_n, ...fastTaps(shapes, m.roughness, m.mid, lv.weight, lv.trilinear, js, nextR(lv)) };
        return t;
    });
    const tapDiff = (t, e) => {
        if (t.count !== e.count) return { count: t.count, expected: e.count };
        let d = 0;
        for (let k = 0; k < 4 * e.count; ++k) d = Math.max(d, Math.abs(t.taps[k] - e.taps[k]), Math.abs(t.info[k] - e.info[k]));
        return { max_abs: d, factor: t.factor, expected_factor: e.factor, tail_share: t.tail_share, expected_tail_share: e.tail_share || 0 };
    };
    const tapsDiff = fx.levels.map((lv, i) => {
        const d = tapDiff(jsTaps[i], lv);
        if (lv.mid) d.mid = jsTaps[i].mid ? tapDiff(jsTaps[i].mid, lv.mid) : { count: 0, expected: lv.mid.count };
        return d;
    });
    const jsPeaks = fx.levels.map((lv) => makePeakLevel(split.peaks, n0, js.levels.length, lv.roughness, lv.weight));
    // The levels by spherical harmonics: the band choice, the projection of the viewer's packing
    // onto each weight's most bands, and each level's texture against the C++ one (relative to the
    // largest coefficient of its row: the projection here is in double, the C++'s float lanes).
    const jsBands = fx.levels.map((lv) => shBands(lv.roughness, lv.weight));
    const projections = new Map();
    for (const w of ['nl', 'g1']) {
        const most = Math.max(0, ...fx.levels.map((lv, i) => (lv.weight === w ? jsBands[i] : 0)));
        if (most > 0) projections.set(w, shProject(js, most));
    }
    const jsSh = fx.levels.map((lv, i) => shLevel(projections.get(lv.weight), lv.roughness, lv.weight, jsBands[i]));
    // The same projection on the GPU (sh_project.frag.glsl) from the viewer's packing.
    const projectProgram = compile(gl, VERTEX, HEADER + (await libraryGlsl()) + '\n' + (await fetchText('sh_project.frag.glsl')));
    packedTexture(gl, js.data, fx.width);
    const gpuProjections = new Map();
    for (const [w, pr] of projections) gpuProjections.set(w, gpuShProject(gl, projectProgram, vao, js, pr.bands));
    const gpuSh = fx.levels.map((lv, i) => shLevel(gpuProjections.get(lv.weight), lv.roughness, lv.weight, jsBands[i]));
    const shDiffOf = (levelsSh, projs) => fx.levels.map((lv, i) => {
        const got = levelsSh[i], proj = projs.get(lv.weight);
        const d = { bands: got.sh_bands, expected_bands: lv.sh_bands, face: proj ? proj.face : 0, expected_face: lv.projection_face };
        if (got.sh.length !== lv.sh.length) return { ...d, size: got.sh.length, expected_size: lv.sh.length };
        const pairs = got.sh.length / 12, rel = [0, 0, 0];
        for (let row = 0; row < 3; ++row) {
            let big = 0, worst = 0;
            for (let k = 4 * pairs * row; k < 4 * pairs * (row + 1); ++k) big = Math.max(big, Math.abs(lv.sh[k]));
            for (let k = 4 * pairs * row; k < 4 * pairs * (row + 1); ++k) worst = Math.max(worst, Math.abs(got.sh[k] - lv.sh[k]));
            rel[row] = big > 0 ? worst / big : worst;
        }
        return { ...d, cosine_max_rel: rel[0], sine_max_rel: rel[1], recurrence_max_rel: rel[2] };
    });
    const shDiff = shDiffOf(jsSh, projections), shGpuDiff = shDiffOf(gpuSh, gpuProjections);
    const peaksDiff = fx.levels.map((lv, i) => {
        const p = jsPeaks[i];
        if (p.peak_count !== lv.peak_count || p.g1 !== lv.g1) return { count: p.peak_count, expected: lv.peak_count };
        let dir = 0, energy = 0;
        for (let j = 0; j < 6 * p.peak_count; ++j) {
            const d = Math.abs(p.peaks[j] - lv.peaks[j]);
            if (j % 6 < 3) dir = Math.max(dir, d);
            else energy = Math.max(energy, d / Math.max(1e-30, Math.abs(lv.peaks[j])));
        }
        return { count: p.peak_count, dir_max_abs: dir, energy_max_rel: energy, a2: p.a2, expected_a2: lv.a2 };
    });
    // Each level into two RGBA32F targets (the texels, and the texels before their peaks), read back
    // face by face (rows from y = 0: the chain's order). The levels go coarse to fine per weight, and
    // a coarse tail reads the GPU's own next level before its peaks (read back, packed by packSource).
    // A level with an intermediate level (lv.mid: n, taps, its tail's share) has it rendered as one
    // more level just before it (no peaks, its tail from the next level, not posted), and reads its
    // own coarse tail from it.
    const render = (levels) => {
        const out = [], before = new Map();
        const all = [];
        for (const lv of levels) {
            lv.key = `${lv.weight}/${lv.level}`;
            lv.order = lv.level;
            lv.nextKey = `${lv.weight}/${lv.level + 1}`;
            if (lv.mid) {
                all.push({ ...lv.mid, level: lv.level, weight: lv.weight, peak_count: 0, sh_bands: 0, isMid: true,
                           key: `${lv.weight}/mid${lv.level}`, order: lv.level + 0.5, nextKey: lv.nextKey });
                lv.nextKey = `${lv.weight}/mid${lv.level}`;
            }
            all.push(lv);
        }
        const ordered = all.sort((a, b) => (a.weight === b.weight ? b.order - a.order : a.weight < b.weight ? -1 : 1));
        for (const lv of ordered)
            lv.next = () => {
                const nx = before.get(lv.nextKey);
                const m = nx.n, at = (f, x, y) => { const k = 3 * ((f * m + y) * m + x); return [nx.rgb[k], nx.rgb[k + 1], nx.rgb[k + 2]]; };
                return { n: m, data: packSource(m, at, null, 1).data };
            };
        const fb = gl.createFramebuffer();
        gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
        gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1]);
        let rgb = null, base = null;
        const target = (n, attachment) => {
            const tex = gl.createTexture();
            gl.bindTexture(gl.TEXTURE_2D, tex);
            gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, n, n, 0, gl.RGBA, gl.FLOAT, null);
            gl.framebufferTexture2D(gl.FRAMEBUFFER, attachment, gl.TEXTURE_2D, tex, 0);
        };
        const readBack = (n, attachment, into) => {
            const px = new Float32Array(4 * n * n);
            gl.readBuffer(attachment);
            gl.readPixels(0, 0, n, n, gl.RGBA, gl.FLOAT, px);
            for (let k = 0; k < n * n; ++k) into.push(px[4 * k], px[4 * k + 1], px[4 * k + 2]);
        };
        prefilterPasses(gl, program, vao, ordered, (lv, f) => {
            if (f !== 0) return;
            gl.activeTexture(gl.TEXTURE2); // the render targets bind here, on no sampler's unit
            target(lv.n, gl.COLOR_ATTACHMENT0);
            target(lv.n, gl.COLOR_ATTACHMENT1);
            rgb = [];
            base = [];
        }, (lv, f) => {
            readBack(lv.n, gl.COLOR_ATTACHMENT0, rgb);
            readBack(lv.n, gl.COLOR_ATTACHMENT1, base);
            if (f === 5) {
                if (!lv.isMid) out.push({ level: lv.level, weight: lv.weight, n: lv.n, rgb });
                before.set(lv.key, { n: lv.n, rgb: base });
            }
        });
        gl.readBuffer(gl.COLOR_ATTACHMENT0);
        return out;
    };
    packedTexture(gl, Float32Array.from(fx.packed), fx.width);
    const levels = render(fx.levels.map((lv) => ({ ...lv })));
    // The whole live path: the viewer's packing and taps through the same shader.
    packedTexture(gl, js.data, fx.width);
    const jsLevels = render(fx.levels.map((lv, i) => ({ level: lv.level, weight: lv.weight, n: lv.n, ...jsTaps[i], ...jsPeaks[i],
                                                        ...jsSh[i] })));
    await post({ kind: 'prefilter', levels, js_levels: jsLevels, packed_max_rel: packedDiff,
                 packed_max_rel_base: packedDiffBase, taps: tapsDiff, mid: midDiff, peaks: peaksDiff, sh: shDiff, sh_gpu: shGpuDiff,
                 source_peaks: split.peaks.length, threshold: split.threshold, renderer: rendererName(gl) });
}

/// The live re-filter test: a bake by the fast filter with a float chain (run_browser_test.py
/// --mode refilter: ibl-bake --prefilter fast --ktx2-format rgba32f), re-filtered by
/// Renderer.refilter from its level 0 as the viewer's button does; every re-filtered level is read
/// back from the chain texture and posted with the level as loaded (what ibl::prefilter wrote).
async function runRefilterTest() {
    const bake = await loadBake(urlSource(params.get('bake')));
    const canvas = document.getElementById('view');
    const r = new Renderer(canvas, await libraryGlsl(), await fetchText('viewer.frag.glsl'));
    r.setBake(bake);
    const gl = r.gl, chain = bake.chain;
    const loaded = chain.levels.map((lv) => lv.faces.map((a) => Float32Array.from(a)));
    // The texture's levels >= 1 zeroed first: a level the re-filter did not draw cannot pass.
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, r.chainTex);
    for (let k = 1; k < chain.levels.length; ++k)
        for (let f = 0; f < 6; ++f) {
            const n = chain.levels[k].size;
            gl.texSubImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + f, k, 0, 0, n, n, gl.RGBA, gl.FLOAT, new Float32Array(4 * n * n));
        }
    const t = r.refilter(await fetchText('prefilter.frag.glsl'), await fetchText(glslBase + '../bake/prefilter_fast_tables.hpp'),
                         await fetchText('sh_project.frag.glsl'));
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.readBuffer(gl.COLOR_ATTACHMENT0);
    const levels = [];
    for (let k = 1; k < chain.levels.length; ++k) {
        const n = chain.levels[k].size, cpp = [], gpu = [];
        for (let f = 0; f < 6; ++f) {
            gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_CUBE_MAP_POSITIVE_X + f, r.chainTex, k);
            const px = new Float32Array(4 * n * n);
            gl.readPixels(0, 0, n, n, gl.RGBA, gl.FLOAT, px);
            for (let i = 0; i < n * n; ++i)
                for (let c = 0; c < 3; ++c) gpu.push(px[4 * i + c]), cpp.push(loaded[k][f][4 * i + c]);
        }
        levels.push({ level: k, n, cpp, gpu });
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    await post({ kind: 'refilter', levels, timing: t, renderer: rendererName(gl) });
}

/// The BC6H decoder test: the fixtures' blocks (tests/browser/bc6h_fixtures.cpp, served as
/// bc6h_fixtures.json) uploaded as one COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT_EXT texture, `blocks_per_row`
/// blocks per block row, every texel read by texelFetch into an RGBA32F target and posted as the
/// target's float bits (rows from y = 0 = the texture's t = 0). Without EXT_texture_compression_bptc
/// (or float render targets) it posts kind 'skip' with the reason and the browser's extensions.
async function runBc6hTest() {
    const canvas = document.getElementById('view');
    const gl = canvas.getContext('webgl2');
    if (!gl) throw new Error('WebGL2 is not available');
    const missing = ['EXT_texture_compression_bptc', 'EXT_color_buffer_float'].filter((e) => !gl.getExtension(e));
    if (missing.length) {
        await post({ kind: 'skip', reason: `this WebGL2 lacks ${missing.join(' and ')}`, renderer: rendererName(gl),
                     extensions: gl.getSupportedExtensions() });
        return;
    }
    const bptc = gl.getExtension('EXT_texture_compression_bptc');
    const fx = JSON.parse(await fetchText(params.get('bake') + 'bc6h_fixtures.json'));
    const raw = Uint8Array.from(atob(fx.blocks), (c) => c.charCodeAt(0));
    const per = fx.blocks_per_row, count = raw.length / 16, rows = Math.ceil(count / per);
    const W = 4 * per, H = 4 * rows;
    const data = new Uint8Array(16 * per * rows); // the last block row padded with zero blocks
    data.set(raw);
    const tex = gl.createTexture();
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.compressedTexImage2D(gl.TEXTURE_2D, 0, bptc.COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT_EXT, W, H, 0, data);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAX_LEVEL, 0);
    const upload = gl.getError();
    if (upload !== gl.NO_ERROR) throw new Error(`compressedTexImage2D (BC6H ${W} x ${H}) failed: GL error 0x${upload.toString(16)}`);
    const program = compile(gl, VERTEX, HEADER + 'uniform highp sampler2D u_blocks;\nout vec4 o_color;\n' +
                            'void main() { o_color = texelFetch(u_blocks, ivec2(gl_FragCoord.xy), 0); }\n');
    gl.activeTexture(gl.TEXTURE1); // the render target binds here, on no sampler's unit
    const target = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, target);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, W, H, 0, gl.RGBA, gl.FLOAT, null);
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, target, 0);
    if (gl.checkFramebufferStatus(gl.FRAMEBUFFER) !== gl.FRAMEBUFFER_COMPLETE) throw new Error('the RGBA32F target is incomplete');
    gl.viewport(0, 0, W, H);
    gl.useProgram(program);
    gl.uniform1i(gl.getUniformLocation(program, 'u_blocks'), 0);
    gl.bindVertexArray(gl.createVertexArray());
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    const out = new Float32Array(4 * W * H);
    gl.readPixels(0, 0, W, H, gl.RGBA, gl.FLOAT, out);
    const err = gl.getError();
    if (err !== gl.NO_ERROR) throw new Error(`GL error 0x${err.toString(16)}`);
    await post({ kind: 'bc6h', width: W, height: H, blocks: count, rgba: toBase64(new Uint8Array(out.buffer)),
                 renderer: rendererName(gl), version: gl.getParameter(gl.VERSION) });
}

// ---- interactive viewer ----------------------------------------------------------------------------

async function runViewer() {
    const canvas = document.getElementById('view');
    const renderer = new Renderer(canvas, await libraryGlsl(), await fetchText('viewer.frag.glsl'));
    const el = (id) => document.getElementById(id);
    const view = { mode: 1, roughness: 0.25, ev: 0, lookup: 'bake', multiscatter: true, light: false, ss: 1, yaw: 0, pitch: 0 };
    let ready = false, pending = false;
    const redraw = () => {
        if (!ready || pending) return;
        pending = true;
        requestAnimationFrame(() => {
            pending = false;
            const grid = view.mode === 0;
            const dpr = grid ? 1 : Math.min(window.devicePixelRatio || 1, 2);
            canvas.width = grid ? 640 : Math.floor(canvas.clientWidth * dpr);
            canvas.height = grid ? 256 : Math.floor(canvas.clientHeight * dpr);
            canvas.style.width = grid ? '640px' : '100vw';
            canvas.style.height = grid ? '256px' : '100vh';
            canvas.style.margin = grid ? '8px 0 0 400px' : '0'; // beside the panel
            renderer.draw(view);
        });
    };
    const bind = (id, key, parse, show) => {
        const input = el(id);
        const initial = params.get(id); // ?roughness=0.5&ev=1&lookup=textbook&grid=1 ...
        if (initial !== null) {
            if (input.type === 'checkbox') input.checked = initial === '1';
            else input.value = initial;
        }
        const update = () => { view[key] = parse(input); if (show) el(id + '_v').textContent = show(view[key]); redraw(); };
        input.addEventListener('input', update);
        update();
    };
    bind('roughness', 'roughness', (i) => +i.value, (v) => v.toFixed(2));
    bind('ev', 'ev', (i) => +i.value, (v) => (v >= 0 ? '+' : '') + v.toFixed(1));
    bind('lookup', 'lookup', (i) => i.value);
    bind('scatter', 'multiscatter', (i) => i.value === '1');
    bind('grid', 'mode', (i) => (i.checked ? 0 : 1));
    bind('light', 'light', (i) => i.checked);
    bind('ss', 'ss', (i) => +i.value);
    let drag = null;
    canvas.addEventListener('pointerdown', (e) => { drag = [e.clientX, e.clientY, view.yaw, view.pitch]; canvas.setPointerCapture(e.pointerId); });
    canvas.addEventListener('pointermove', (e) => {
        if (!drag) return;
        view.yaw = drag[2] + (e.clientX - drag[0]) * 0.005;
        view.pitch = Math.max(-1.5, Math.min(1.5, drag[3] + (e.clientY - drag[1]) * 0.005));
        redraw();
    });
    canvas.addEventListener('pointerup', () => { drag = null; });
    window.addEventListener('resize', redraw);
    const open = async (src) => {
        statusEl.textContent = '';
        try {
            const bake = await loadBake(src);
            renderer.setBake(bake);
            ready = true;
            const i = renderer.info();
            log(`${bake.label}: chain ${i.chain_levels.join('/')} ${i.chain_format}, LUT ${i.lut_size}^2 (${i.lut_texture}), ` +
                `lookup ${renderer.rt.spec.name || renderer.rt.spec.weight}, runtime ${i.runtime_model}` +
                (i.lobe_size ? ` (lobe LUT ${i.lobe_size}^2)` : '') + (i.taps_size ? ` (two-tap table ${i.taps_size}^2)` : '') + `, diffuse ${renderer.rt.diffuse}, ` +
                `sun ${bake.sun ? bake.sun.solidAngle.toPrecision(3) + ' sr' : 'none'}\n${i.renderer}`);
            redraw();
        } catch (e) {
            log(String(e.message || e));
        }
    };
    el('folder').addEventListener('change', (e) => open(fileSource(e.target.files)));
    const refilter = async () => {
        if (!ready) return;
        try {
            const t = renderer.refilter(await fetchText('prefilter.frag.glsl'), await fetchText(glslBase + '../bake/prefilter_fast_tables.hpp'),
                                        await fetchText('sh_project.frag.glsl'));
            el('refilter_v').textContent = `${t.levels} levels, ${t.peaks} peaks: ${t.gpu_ms.toFixed(1)} ms GPU + ${t.prepare_ms.toFixed(1)} ms CPU`;
            redraw();
        } catch (e) {
            log(String(e.message || e));
        }
    };
    el('refilter').addEventListener('click', refilter);
    if (params.get('bake')) await open(urlSource(params.get('bake')));
    if (params.get('refilter') === '1') await refilter(); // ?refilter=1: re-filter once the bake is loaded
    else log('choose a bake folder (ibl-bake --out DIR), or open this page with ?bake=URL');
}

async function main() {
    if (testMode) document.body.classList.add('test');
    try {
        if (testMode === 'preview') await runPreviewTest();
        else if (testMode === 'numeric') await runNumericTest();
        else if (testMode === 'prefilter') await runPrefilterTest();
        else if (testMode === 'refilter') await runRefilterTest();
        else if (testMode === 'bc6h') await runBc6hTest();
        else await runViewer();
    } catch (e) {
        log(String(e.stack || e));
        if (testMode) await post({ kind: 'error', error: String(e.stack || e) });
    }
}

window.addEventListener('error', (e) => { if (testMode) post({ kind: 'error', error: String(e.message) }); });
main();
