#version 460
// One level of the RSM quadtree (ALGORITHM.md section 2, "A patch P"): each
// texel of level k merges its four children of level k-1. Flux and solid angle
// add up, area adds up, position is the area-weighted mean and the normal the
// normalised area-weighted mean.
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D src_position;  // xyz: position; w: area A
layout(set = 0, binding = 1, rgba32f) readonly uniform image2D src_normal;    // xyz: normal; w: 1 if seen
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D src_flux;      // rgb: flux; a: solid angle
layout(set = 0, binding = 3, rgba32f) writeonly uniform image2D dst_position;
layout(set = 0, binding = 4, rgba32f) writeonly uniform image2D dst_normal;
layout(set = 0, binding = 5, rgba32f) writeonly uniform image2D dst_flux;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(dst_position)))) return;
    vec4 flux = vec4(0.0);
    vec3 weighted_position = vec3(0.0);
    vec3 weighted_normal = vec3(0.0);
    float area = 0.0;
    float seen = 0.0;
    for (int i = 0; i < 4; ++i) {
        ivec2 c = 2 * p + ivec2(i & 1, i >> 1);
        vec4 pos = imageLoad(src_position, c);
        vec4 nrm = imageLoad(src_normal, c);
        flux += imageLoad(src_flux, c);
        weighted_position += pos.w * pos.xyz;
        weighted_normal += pos.w * nrm.xyz;
        area += pos.w;
        seen = max(seen, nrm.w);
    }
    vec3 position = area > 0.0 ? weighted_position / area : vec3(0.0);
    vec3 normal = dot(weighted_normal, weighted_normal) > 0.0 ? normalize(weighted_normal) : vec3(0.0);
    imageStore(dst_position, p, vec4(position, area));
    imageStore(dst_normal, p, vec4(normal, seen));
    imageStore(dst_flux, p, flux);
}
