#version 460
#extension GL_GOOGLE_include_directive : require
#define SHADE_COMBINED 0
#include "stages/shade_body.glsl"
