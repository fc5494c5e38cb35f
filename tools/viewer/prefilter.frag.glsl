// tools/viewer/prefilter.frag.glsl — one face of one prefiltered level (ibl_prefilter.glsl): pixel
// (x, y) of the n x n RGBA32F target is texel (x, y) of face u_face (readPixels returns row y = 0
// first, the cubemap's row order).

uniform sampler2D u_src, u_taps;
uniform int u_count, u_face, u_n;
uniform float u_factor;
out vec4 o_color;

void main() {
    vec3 dir = ibl_cube_texel_direction(u_face, int(gl_FragCoord.x), int(gl_FragCoord.y), u_n);
    o_color = vec4(ibl_prefilter_texel(u_src, u_taps, u_count, u_factor, dir), 1.0);
}
