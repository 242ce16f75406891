#version 330
uniform vec3 u_eye;
uniform vec3 u_light_position;
uniform vec3 u_light_Ip;
uniform vec3 u_Od;
uniform float u_ks;
uniform float u_n;
in vec3 v_position;
in vec3 v_normal;
out vec4 f_color;

void main() {
    vec3 n = normalize(v_normal);
    vec3 l = u_light_position - v_position;
    float d2 = dot(l, l);
    l = normalize(l);
    vec3 v = normalize(u_eye - v_position);
    vec3 r = 2.0 * n * dot(n, l) - l;
    float diffuse = max(dot(n, l), 0.0);
    float specular = diffuse > 0.0 ? pow(max(dot(r, v), 1e-12), u_n) : 0.0;
    f_color = vec4(u_light_Ip / d2 * (u_Od * diffuse + u_ks * specular), 1.0);
}
