#version 460
#extension GL_GOOGLE_include_directive : require
// Method vct, pass vct-trace (docs/algorithm.md section 9.3): every pixel
// traces VCT_CONES diffuse cones through the radiance volume and sums
//   E = sum_k w_k L_k,   sum_k w_k = pi
// (src/methods/vct/cones.rs: one cone of half angle 30 degrees along the
// normal, weight pi / 4; the rest in a ring 60 degrees off it, 3 pi / 4
// shared). A cone starts one cell off the surface along the normal, and
// steps half its diameter d at a time, reading the level whose cells are d
// wide (trilinear between cells and levels), front to back:
//   a' = 1 - (1 - a)^(step / cell),  L += (1 - alpha) c a' / a,
//   alpha += (1 - alpha) a'
// (c, a the premultiplied colour and opacity read; a' the opacity of the
// step's length), until alpha reaches 0.95 or the cone is a diameter past
// the grid.
// With VCT_LOBE cells are one-sided: a cell's light goes only to the side
// its lit surface faces, c scaled by the facing term
//   f(m) = (1 - |m|) + |m| clamp(1/2 - 2 d.m^, 0, 1),
// m the lit surface's mean normal (vct/mips.comp), and a cell blocks only
// cones that meet its surface's front, c and a scaled by f(s), s the
// surface's mean normal (a wall with both faces in one cell has |s| = 0
// and blocks both ways). So a surface neither lights nor shadows itself:
// the cone leaving a floor passes the floor's own coarse cells.
#include "frame.glsl"
#include "vct/vct.glsl"

layout(constant_id = 91) const int VCT_LEVELS = 7;
layout(constant_id = 92) const int VCT_CONES = 6;
layout(constant_id = 93) const bool VCT_LOBE = true;
layout(constant_id = 94) const float VCT_RING_TAN = 0.57735;  // cones::ring_half_angle

layout(set = 1, binding = 0) uniform sampler2D gbuffer_position;
layout(set = 1, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 1, binding = 2) uniform sampler3D vct_radiance;  // rgb: L alpha; a: alpha
layout(set = 1, binding = 3) uniform sampler3D vct_lobe;      // xyz: m w; w: w
layout(set = 1, binding = 4) uniform sampler3D vct_surface;   // xyz: s alpha; w: alpha

layout(location = 0) out vec4 out_irradiance;  // rgb: E (W/m^2)

// A step is half the cone's diameter; the march stops at this opacity.
const float STEP = 0.5;
const float OPAQUE = 0.95;
const float CAP_TAN = 0.57735026919;  // tan 30 degrees

// The facing term of a lobe (xyz: a mean normal times w; w) for a cone
// going along `dir`: 1 where the normal faces the cone's apex, 0 where it
// faces away, 1 where normals disagree.
float facing(vec4 lobe, vec3 dir) {
    // Trilinear tails leave denormal weights, which a division may flush.
    if (!(lobe.w > 1e-20)) {
        return 1.0;
    }
    vec3 m = lobe.xyz / lobe.w;
    float len = length(m);
    if (!(len > 1e-4)) {
        return 1.0;
    }
    float k = min(len, 1.0);
    return (1.0 - k) + k * clamp(0.5 - 2.0 * dot(dir, m) / len, 0.0, 1.0);
}

// The radiance arriving along the cone from `origin` in direction `dir`.
vec3 cone(vec3 origin, vec3 dir, float tan_half) {
    float h = u.grid_cube.w;
    float side = float(VCT_SIZE) * h;
    float top = float(VCT_LEVELS - 1);
    vec3 c = vec3(0.0);
    float alpha = 0.0;
    float t = h;
    // At most 3 log2(N) / log2(1 + tan) + a few steps cross the grid; the
    // bound only guards against a runaway loop.
    for (int i = 0; i < 512 && alpha < OPAQUE; ++i) {
        float d = max(h, 2.0 * t * tan_half);
        float lod = min(log2(d / h), top);
        vec3 uvw = (origin + t * dir - u.grid_cube.xyz) / side;
        // Past the grid by more than the cone's width, nothing is left to
        // read; within a width of it the cone still covers the cells on
        // the edge (a wall on the scene's bounds, which the last step
        // inside may only graze), so it reads them there.
        float out_by = max(max(-min(uvw.x, min(uvw.y, uvw.z)), max(uvw.x, max(uvw.y, uvw.z)) - 1.0), 0.0);
        if (out_by * side > d) {
            break;
        }
        uvw = clamp(uvw, vec3(0.0), vec3(1.0));
        vec4 s = textureLod(vct_radiance, uvw, lod);
        float step = STEP * d;
        float a = clamp(s.a, 0.0, 1.0);
        float ratio = step / (h * exp2(lod));
        float a_step = 1.0 - pow(1.0 - a, ratio);
        vec3 colour = s.rgb * (a > 1e-6 ? a_step / a : ratio);
        if (VCT_LOBE) {
            float front = facing(textureLod(vct_surface, uvw, lod), dir);
            colour *= front * facing(textureLod(vct_lobe, uvw, lod), dir);
            a_step *= front;
        }
        c += (1.0 - alpha) * colour;
        alpha += (1.0 - alpha) * a_step;
        t += step;
    }
    return c;
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(gbuffer_position, pixel, 0);
    vec3 e = vec3(0.0);
    if (p.w > 0.0) {
        vec3 n = normalize(texelFetch(gbuffer_normal, pixel, 0).xyz);
        // A frame about n (Duff et al. 2017).
        float sgn = n.z >= 0.0 ? 1.0 : -1.0;
        float a = -1.0 / (sgn + n.z);
        float b = n.x * n.y * a;
        vec3 tx = vec3(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
        vec3 ty = vec3(b, sgn + n.y * n.y * a, -n.y);
        vec3 origin = p.xyz + u.grid_cube.w * n;
        e += (PI / 4.0) * cone(origin, n, CAP_TAN);
        int ring = VCT_CONES - 1;
        float w = 0.75 * PI / float(ring);
        // 60 degrees off the normal.
        const float S = 0.86602540378, C = 0.5;
        for (int k = 0; k < ring; ++k) {
            float phi = 2.0 * PI * float(k) / float(ring);
            vec3 dir = S * (cos(phi) * tx + sin(phi) * ty) + C * n;
            e += w * cone(origin, dir, VCT_RING_TAN);
        }
    }
    out_irradiance = vec4(e, 0.0);
}
