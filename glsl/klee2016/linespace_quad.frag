// Screen-filling triangle, fragment stage — Klee 2016, ch. 4.1 (Fig. 7, third phase): the
// diffuse texture (shadow value already multiplied in by the compute pass) is read as a
// sampler2D and every pixel written to the framebuffer (headless: an FBO read back into the PNG).
in vec2 texCoord;
layout(binding = SAMPLER_QUAD_COLOR) uniform sampler2D colorTexture;
layout(location = 0) out vec4 fragColor;

void main()
{
    fragColor = vec4(texture(colorTexture, texCoord).rgb, 1.0);
}
