#version 460
// Pass `bounce-add` (docs/algorithm.md section 5.9): every pixel adds the
// light of bounces 2..N to the method's indirect irradiance, upsampled from
// the four nearest receivers of `bounce-gather` with bilinear weights times
// how alike their normals and planes are to the pixel's (a joint bilateral
// filter, as the methods' own upsampling): light does not bleed across an
// edge between surfaces.
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"
#include "bounce/bounce.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 1, binding = 0) uniform sampler2D gbuffer_position;
layout(set = 1, binding = 1) uniform sampler2D gbuffer_normal;
layout(set = 1, binding = 2, std430) readonly buffer BounceReceived { vec4 received[]; };
layout(set = 1, binding = 3, rgba32f) uniform image2D indirect;

void main() {
    ivec2 size = ivec2(run.output_size);
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, size))) return;
    vec4 p = texelFetch(gbuffer_position, pixel, 0);
    if (p.w <= 0.0) return;
    vec3 n = normalize(texelFetch(gbuffer_normal, pixel, 0).xyz);
    ivec2 low = (size + BOUNCE_STEP - 1) / BOUNCE_STEP;
    // Receiver q sits at pixel q * STEP + STEP / 2: in receiver units the
    // pixel's centre is at f.
    vec2 f = (vec2(pixel) + 0.5 - float(BOUNCE_STEP / 2) - 0.5) / float(BOUNCE_STEP);
    ivec2 q0 = ivec2(floor(f));
    vec2 w = f - vec2(q0);
    vec3 e = vec3(0.0);
    float weight = 0.0;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 q = clamp(q0 + o, ivec2(0), low - 1);
        ivec2 sp = min(q * BOUNCE_STEP + BOUNCE_STEP / 2, size - 1);
        vec4 ps = texelFetch(gbuffer_position, sp, 0);
        if (ps.w <= 0.0) continue;
        vec3 ns = normalize(texelFetch(gbuffer_normal, sp, 0).xyz);
        float bilinear = (o.x == 1 ? w.x : 1.0 - w.x) * (o.y == 1 ? w.y : 1.0 - w.y);
        // The plane's distance against 2% of the view depth: a step in depth
        // is another surface.
        float plane = abs(dot(n, ps.xyz - p.xyz)) / (0.02 * p.w);
        float alike = pow(max(dot(n, ns), 0.0), 8.0) / (1.0 + plane * plane);
        // A small floor keeps a pixel with no alike receiver near its own.
        float wk = bilinear * (alike + 1e-3) + 1e-6;
        e += wk * received[q.x + low.x * q.y].rgb;
        weight += wk;
    }
    if (weight <= 0.0) return;
    vec4 old = imageLoad(indirect, pixel);
    imageStore(indirect, pixel, vec4(old.rgb + e / weight, old.a));
}
