// The pipelines of `StripRenderer` (strips and triangle lists alike):
// positions through the caller's view-projection matrix, Lambert lighting
// from one directional light on the interpolated vertex normals, a surface
// colour of base colour × base-colour texture × vertex colour.

struct Camera {
    view_proj: mat4x4<f32>,
    // xyz: unit direction towards the light (world space); w: 1 to shade
    // with it, 0 for the unlit base colour (coverage only).
    light_dir: vec4<f32>,
    // rgb: base colour of the surface (linear); a unused.
    colour: vec4<f32>,
    // x: 1 to multiply by the texture, y: 1 to multiply by the vertex
    // colours; 0 leaves the factor out, so that a renderer with neither
    // computes exactly what it did before textures existed (an
    // interpolated constant 1 need not come out as exactly 1).
    material: vec4<f32>,
};

@group(0) @binding(0) var<uniform> camera: Camera;
// RGBA8 sRGB with a full mip chain (1 × 1 white when untextured).
@group(0) @binding(1) var base_texture: texture_2d<f32>;
// Trilinear, repeating.
@group(0) @binding(2) var base_sampler: sampler;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    // Per instance: model to world (rotation, uniform scale, translation),
    // by columns. A single object is one identity instance.
    @location(2) model_0: vec4<f32>,
    @location(3) model_1: vec4<f32>,
    @location(4) model_2: vec4<f32>,
    @location(5) model_3: vec4<f32>,
    // v up (OpenGL, OBJ): v = 0 is the image's bottom row.
    @location(6) uv: vec2<f32>,
    // Linear RGBA (Unorm16x4 in the buffer).
    @location(7) colour: vec4<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) colour: vec4<f32>,
};

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    let model = mat4x4<f32>(v.model_0, v.model_1, v.model_2, v.model_3);
    out.clip = camera.view_proj * (model * vec4<f32>(v.position, 1.0));
    // Uniform scale only: the upper 3x3 keeps normals perpendicular, and
    // the fragment stage normalises.
    out.normal = (model * vec4<f32>(v.normal, 0.0)).xyz;
    // Texture rows run top to bottom: flip v.
    out.uv = vec2<f32>(v.uv.x, 1.0 - v.uv.y);
    out.colour = v.colour;
    return out;
}

const AMBIENT: f32 = 0.18;

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    // Sampled before any branch: implicit derivatives need uniform control
    // flow.
    let texel = textureSample(base_texture, base_sampler, in.uv);
    if (camera.light_dir.w == 0.0) {
        return vec4<f32>(camera.colour.rgb, 1.0);
    }
    var albedo = camera.colour.rgb;
    if (camera.material.x != 0.0) {
        albedo = albedo * texel.rgb;
    }
    if (camera.material.y != 0.0) {
        albedo = albedo * in.colour.rgb;
    }
    // A vertex without a triangle at LoD 0 has a zero normal: light it as
    // if it faced the light rather than dividing by zero.
    let len2 = dot(in.normal, in.normal);
    var diffuse = 1.0;
    if (len2 > 1e-20) {
        diffuse = max(dot(in.normal * inverseSqrt(len2), camera.light_dir.xyz), 0.0);
    }
    let shade = AMBIENT + (1.0 - AMBIENT) * diffuse;
    return vec4<f32>(albedo * shade, 1.0);
}
