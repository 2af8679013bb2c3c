#version 460
// A compute shader that does nothing: tender-bench times chains of its dispatches, each followed
// by a pipeline barrier, to measure what one dispatch of a pass costs on the device.
layout(local_size_x = 64) in;

void main() {}
