//VTK::System::Dec
// GPU silhouettes (Brabec, "Shadow Techniques for Interactive and Real-Time Applications", PhD
// thesis, 2003, ch. 9, as a geometry-shader variant): welded vertices of the
// closed components in the geometry's rebased frame. The index travels along so that the
// geometry stage can evaluate every face's facing in one canonical vertex order.
in vec3 vertexRebased;

out vec3 positionGS;
flat out int indexGS;

void main()
{
  positionGS = vertexRebased;
  indexGS = gl_VertexID;
}
