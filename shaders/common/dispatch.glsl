// The item and work group of a kernel launched by gpu::Queue::dispatch_items / dispatch_groups. Past
// GL_MAX_COMPUTE_WORK_GROUP_COUNT[0] groups (65535 on llvmpipe and many drivers: 16.7M items of 256)
// the queue lays the groups out in rows of a 2D grid, so kernels number items and groups through
// these, never through gl_GlobalInvocationID.x. The last row may hold groups past the end: kernels
// test the item against their count, and kernels that write one value per group return when the
// group's first item is past it.
#ifndef TETRASAND_COMMON_DISPATCH_GLSL
#define TETRASAND_COMMON_DISPATCH_GLSL

// Macros, not functions: gl_WorkGroupSize exists only after the kernel's layout(local_size_x = ...)
// declaration, which comes after its includes (Mesa rejects a function body that names it earlier).
#define dispatch_group() (gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x)
#define dispatch_item() (dispatch_group() * gl_WorkGroupSize.x + gl_LocalInvocationID.x)

#endif
