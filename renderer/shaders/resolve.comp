#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
layout(local_size_x = CAMHEAD_TILE_X, local_size_y = CAMHEAD_TILE_Y) in;
void main() {}
