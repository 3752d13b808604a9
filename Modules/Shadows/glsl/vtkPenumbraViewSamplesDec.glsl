// Penumbra view samples, declarations (inserted after the mapper's light declarations,
// after vtkPenumbraSurfaceDec.glsl).
uniform float penumbraPropIndex;    // index of the prop in the extracted scene geometry
