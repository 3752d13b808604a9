//VTK::System::Dec
//VTK::Output::Dec
// Shadow-volume mask copy, fragment stage (Brabec, "Shadow Techniques for Interactive and Real-Time
// Applications", PhD thesis, 2003, §8.3, the stencil-to-channel copy): drawn with the stencil
// test "count != 0" and the colour mask on one channel, it writes 0 (shadow) into that light's
// channel of the RGBA mask wherever its volumes left a non-zero count.
void main()
{
  gl_FragData[0] = vec4(0.0);
}
