#version 330
// A patch seen from behind still hides what lies beyond it, but receives nothing: item 0.
flat in uint v_id;
out uint f_id;

void main() {
    f_id = gl_FrontFacing ? v_id : 0u;
}
