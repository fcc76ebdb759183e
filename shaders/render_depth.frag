#version 330 core
// Depth pre-pass: depth only (colour writes are masked off); masked
// materials' cut-out fragments leave no depth.
#include "render_alpha.h"
void main() { loAlphaTest(); }
