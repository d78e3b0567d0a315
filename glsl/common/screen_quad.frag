// Screen-filling quad, fragment stage — Müller 2015, ch. 3.1.3. The output texture (finalTex of
// the shading kernel, RGBA32F: rgb colour, a: accumulated weight) is bound to a texture binding
// point and read through a 2D sampler; its colour textures the screen-filling quad, so the
// rendered image appears on the screen.
// Nearest-texel filtering (set on the texture): at 1:1 size every fragment shows exactly its
// pixel, so a screenshot of the window equals the PNG of `gpgpu-rt render` (colours clamped to
// [0, 1], no gamma, as there).

layout(binding = SAMPLER_QUAD_COLOR) uniform sampler2D outputTexture;

in vec2 texCoord;

layout(location = 0) out vec4 fragColor;

void main()
{
    fragColor = vec4(clamp(texture(outputTexture, texCoord).rgb, 0.0, 1.0), 1.0);
}
