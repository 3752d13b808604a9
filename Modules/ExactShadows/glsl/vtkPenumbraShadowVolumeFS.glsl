//VTK::System::Dec
// Stencil shadow volumes, fragment stage: nothing to write, the stencil operations count.
void main()
{
}
