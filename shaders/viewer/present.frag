#version 460
#extension GL_GOOGLE_include_directive : require
// The viewer's present pass: the frame's image (the tonemapped display image,
// the indirect light alone, or a host-made debug picture) scaled into the
// swapchain image with its aspect kept; letterbox colour around it.
#include "frame.glsl"

layout(set = 1, binding = 0) uniform sampler2D display;   // sRGB-encoded, UNORM
layout(set = 1, binding = 1) uniform sampler2D indirect;  // irradiance E (W/m^2)
layout(set = 1, binding = 2) uniform sampler2D albedo;    // linear
layout(set = 1, binding = 3) uniform sampler2D host_view; // sRGB-encoded, UNORM

layout(push_constant) uniform Push { PresentPush p; };

layout(location = 0) out vec4 out_color;

vec3 srgb_encode(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

vec3 srgb_decode(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(0.04045, c));
}

void main() {
    vec2 local = (gl_FragCoord.xy - vec2(p.rect.xy)) / vec2(p.rect.zw);
    vec3 encoded;
    if (any(lessThan(local, vec2(0.0))) || any(greaterThanEqual(local, vec2(1.0)))) {
        encoded = p.letterbox.rgb;
    } else if (p.view == PRESENT_VIEW_INDIRECT) {
        ivec2 size = textureSize(indirect, 0);
        ivec2 texel = min(ivec2(local * vec2(size)), size - 1);
        vec3 e = texelFetch(indirect, texel, 0).rgb;
        vec3 a = texelFetch(albedo, texel, 0).rgb;
        encoded = srgb_encode(a / PI * e * run.exposure);
    } else if (p.view == PRESENT_VIEW_HOST) {
        encoded = texture(host_view, local).rgb;
    } else {
        encoded = texture(display, local).rgb;
    }
    out_color = vec4(p.srgb_target != 0 ? srgb_decode(encoded) : encoded, 1.0);
}
