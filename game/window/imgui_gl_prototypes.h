#pragma once
// Force-included into Dear ImGui's OpenGL 3 backend in place of its own
// loader: the loader in Debian's ImGui 1.86 writes 54 function pointers
// into a 53-entry array (UBSan stops it). Mesa's libGL exports every GL 3.3
// entry point, so prototypes and the link are enough.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
