//VTK::System::Dec
// GPU silhouettes (seed 004 ch. 9, the note's geometry-shader variant): welded vertices of the
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
