// tools/viewer/room.js — the room example (room.html): the analytic room lit by two local probes,
// every surface a mirror or glossy reflector, the distant lookup beside the parallax-corrected one
// (room.frag.glsl). The scene and the probes' chains come from tests/browser/room_reference.cpp's
// JSON (room_reference > room_fixtures.json; serve it next to the repository):
//   data=URL   the JSON (default room_fixtures.json next to this page)
//   glsl=URL   where ibl_*.glsl live (default ../../include/ibl/glsl/)
//   test=room  render both halves into an RGBA32F target and POST the linear pixels to `report`
//              (tests/browser/run_browser_test.py --mode room compares them with the C++ pixels)
//   ev=        exposure of the display (default 0)
// The chains are uploaded as RGBA16F (their texels are halves already: the upload is exact).

const params = new URLSearchParams(location.search);
const testMode = params.get('test');
const glslBase = params.get('glsl') || '../../include/ibl/glsl/';
const statusEl = document.getElementById('status');
const log = (s) => { statusEl.textContent += s + '\n'; };

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

function rendererName(gl) {
    const ext = gl.getExtension('WEBGL_debug_renderer_info');
    return ext ? gl.getParameter(ext.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
}

async function post(result) {
    const url = params.get('report');
    if (!url) return;
    await fetch(url, { method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(result) });
}

/// One probe's chain as a mipmapped RGBA16F cube on texture unit `unit` (faces in the library's
/// order and orientation, which are GL's).
function uploadChain(gl, unit, levels) {
    const tex = gl.createTexture();
    gl.activeTexture(gl.TEXTURE0 + unit);
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, tex);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    levels.forEach((lv, l) => {
        for (let f = 0; f < 6; ++f) {
            const rgba = new Float32Array(4 * lv.size * lv.size);
            for (let k = 0; k < lv.size * lv.size; ++k) {
                for (let c = 0; c < 3; ++c) rgba[4 * k + c] = lv.faces[f][3 * k + c];
                rgba[4 * k + 3] = 1;
            }
            gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + f, l, gl.RGBA16F, lv.size, lv.size, 0, gl.RGBA, gl.FLOAT, rgba);
        }
    });
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_BASE_LEVEL, 0);
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MAX_LEVEL, levels.length - 1);
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR);
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    for (const w of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T, gl.TEXTURE_WRAP_R]) gl.texParameteri(gl.TEXTURE_CUBE_MAP, w, gl.CLAMP_TO_EDGE);
}

/// Renders both halves (width x height, linear RGB) and returns the RGBA floats, rows from the bottom.
async function render(fx) {
    const gl = document.getElementById('gl').getContext('webgl2');
    if (!gl) throw new Error('WebGL2 is not available');
    if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('EXT_color_buffer_float is needed to render float results');
    const parts = [];
    for (const f of ['ibl_common.glsl', 'ibl_lookup.glsl', 'ibl_local_probe.glsl']) parts.push(await fetchText(glslBase + f));
    const program = compile(gl, VERTEX, HEADER + parts.join('\n') + '\n' + (await fetchText('room.frag.glsl')));
    if (fx.probes.length !== 2) throw new Error(`room.frag.glsl draws two probes, the data has ${fx.probes.length}`);
    fx.probes.forEach((p, i) => uploadChain(gl, i, p.levels));
    const W = fx.width, H = fx.height;
    gl.activeTexture(gl.TEXTURE2); // the render target binds here, on no sampler's unit
    const fb = gl.createFramebuffer(), target = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, target);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, W, H, 0, gl.RGBA, gl.FLOAT, null);
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, target, 0);
    gl.viewport(0, 0, W, H);
    gl.useProgram(program);
    const u = (name) => gl.getUniformLocation(program, name);
    gl.uniform1i(u('u_probe0'), 0);
    gl.uniform1i(u('u_probe1'), 1);
    gl.uniform3fv(u('u_cam'), fx.camera.position);
    gl.uniform3fv(u('u_fwd'), fx.camera.forward);
    gl.uniform3fv(u('u_right'), fx.camera.right);
    gl.uniform3fv(u('u_up'), fx.camera.up);
    gl.uniform2fv(u('u_tan'), fx.camera.tan);
    gl.uniform2f(u('u_half_size'), W / 2, H);
    gl.uniform3fv(u('u_room_lo'), fx.room.lo);
    gl.uniform3fv(u('u_room_hi'), fx.room.hi);
    gl.uniform1fv(u('u_roughness'), fx.roughness);
    gl.uniform3fv(u('u_at'), fx.probes.flatMap((p) => p.at));
    gl.uniform3fv(u('u_infl_lo'), fx.probes.flatMap((p) => p.influence.lo));
    gl.uniform3fv(u('u_infl_hi'), fx.probes.flatMap((p) => p.influence.hi));
    gl.uniform1fv(u('u_fade'), fx.probes.map((p) => p.fade));
    gl.uniform4iv(u('u_priority'), [fx.probes[0].priority, fx.probes[1].priority, 0, 0]);
    gl.uniform1i(u('u_levels'), fx.probes[0].levels.length);
    gl.uniform1i(u('u_half'), -1);
    gl.bindVertexArray(gl.createVertexArray());
    gl.drawArrays(gl.TRIANGLES, 0, 3);
    const out = new Float32Array(4 * W * H);
    gl.readPixels(0, 0, W, H, gl.RGBA, gl.FLOAT, out);
    return { gl, out };
}

/// Reinhard and sRGB to 8 bits (image_png.cpp's tonemap_png), the halves into their canvases.
function display(fx, out, exposure) {
    const W = fx.width, H = fx.height, hw = W / 2;
    const code = (x) => {
        x *= exposure;
        if (!(x > 0)) return 0;
        x = x / (1 + x);
        const y = (x <= 0.0031308 ? 12.92 * x : 1.055 * Math.pow(x, 1 / 2.4) - 0.055) * 255 + 0.5;
        return Math.min(Math.max(Math.floor(y), 0), 255);
    };
    ['left', 'right'].forEach((id, half) => {
        const canvas = document.getElementById(id);
        canvas.width = hw;
        canvas.height = H;
        const ctx = canvas.getContext('2d');
        const img = ctx.createImageData(hw, H);
        for (let y = 0; y < H; ++y)
            for (let x = 0; x < hw; ++x) {
                const s = 4 * ((H - 1 - y) * W + x + half * hw), d = 4 * (y * hw + x);
                for (let c = 0; c < 3; ++c) img.data[d + c] = code(out[s + c]);
                img.data[d + 3] = 255;
            }
        ctx.putImageData(img, 0, 0);
    });
}

async function main() {
    if (testMode) document.body.classList.add('test');
    try {
        const fx = JSON.parse(await fetchText(params.get('data') || 'room_fixtures.json'));
        const { gl, out } = await render(fx);
        if (testMode === 'room') {
            await post({ kind: 'room', width: fx.width, height: fx.height, values: Array.from(out), renderer: rendererName(gl) });
            return;
        }
        display(fx, out, Math.pow(2, +(params.get('ev') || 0)));
        log(`faces ${fx.face}^2, ${fx.probes.length} probes; renderer ${rendererName(gl)}`);
    } catch (e) {
        log(String(e.stack || e));
        if (testMode) await post({ kind: 'error', error: String(e.stack || e) });
    }
}

window.addEventListener('error', (e) => { if (testMode) post({ kind: 'error', error: String(e.message) }); });
main();
