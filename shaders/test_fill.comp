// test_fill.comp - used only by tests/test_context.c: proves that
// lpv_shared.h reaches GLSL (its constants and struct LpvCell) and that an
// SSBO written here reads back on the CPU with the same std430 layout.
layout(local_size_x = 4) in;

layout(std430, binding = LPV_SSBO_LPV_OUT) buffer Cells {
    LpvCell cells[];
};

void main()
{
    uint i = gl_GlobalInvocationID.x;
    float k = float(i);
#ifdef LPV_TEST_FILL_BREAK
    no_such_function(k); // line 15: the test checks that errors point here
#endif
    cells[i].r = vec4(LPV_SH_C0, LPV_SH_C1, LPV_PI, k);
    cells[i].g = vec4(LPV_PROP_A, float(LPV_DIR_COUNT), float(LPV_MAX_GRID_DIM), k + 0.5f);
    cells[i].b = vec4(-1.0f, 0.0f, 1.0f, LPV_FP16_MAX);
}
