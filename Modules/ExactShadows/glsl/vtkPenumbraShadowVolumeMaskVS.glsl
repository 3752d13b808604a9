//VTK::System::Dec
// Shadow-volume mask copy, vertex stage (Brabec, "Shadow Techniques for Interactive and Real-Time
// Applications", PhD thesis, 2003, ch. 8): one triangle covering the
// viewport, from gl_VertexID alone (no vertex buffer).
void main()
{
  vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
