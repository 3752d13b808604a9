  // Penumbra view samples (the last statements of main(), after VTK's lighting, texturing and
  // alpha discard): the surface position relative to the rebasing origin in float32 and its
  // facet normal turned toward the camera (penumbraP, penumbraN: penumbraSurface, computed
  // where control flow is still uniform), the prop index and the mapper's primitive id
  // (split in two exact 16-bit halves). The primitive target repeats the prop index and the
  // valid flag so that it alone identifies the surface: the CPU can read it back and rebuild
  // the position from the triangle.
  {
    int penumbraPrim = gl_PrimitiveID + PrimitiveIDOffset;
    gl_FragData[0] = vec4(penumbraP, 1.0);
    gl_FragData[1] = vec4(penumbraN, penumbraPropIndex);
    gl_FragData[2] = vec4(float(penumbraPrim & 65535), float(penumbraPrim >> 16),
                           penumbraPropIndex, 1.0);
  }
