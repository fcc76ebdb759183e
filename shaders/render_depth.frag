#version 330 core
// Depth pre-pass: depth only (colour writes are masked off).
void main() {}
