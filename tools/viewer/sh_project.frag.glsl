// tools/viewer/sh_project.frag.glsl — the projection of the fast filter's rough levels by spherical
// harmonics on the GPU (ibl_prefilter.glsl ibl_prefilter_sh_project): pixel (p, r) of the
// sh_pair_count(u_bands) x 12 RGBA32F target is pair p (m outer, l = m .. u_bands - 1 inner) of
// face r / 2, its cosine sums (r even) or sine sums (r odd) over the packed source's level u_level
// (n, stride, face stride, offset); alpha: the same sums of a constant 1.

uniform sampler2D u_src;
uniform ivec4 u_level;
uniform int u_bands;
layout(location = 0) out vec4 o_color;

void main() {
    int p = int(gl_FragCoord.x), r = int(gl_FragCoord.y);
    int m = 0, first = 0;
    while (p >= first + (u_bands - m)) { // the pairs of m are [first, first + bands - m)
        first += u_bands - m;
        ++m;
    }
    int l = m + (p - first);
    o_color = ibl_prefilter_sh_project(u_src, u_level, r / 2, l, m, (r % 2) == 1);
}
