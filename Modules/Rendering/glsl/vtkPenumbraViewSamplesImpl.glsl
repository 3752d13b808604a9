  // Penumbra view samples (appended after the mapper's lighting code): the surface position
  // relative to the rebasing origin in float32, its facet normal turned toward the camera
  // (penumbraSurface), the prop index and the mapper's primitive id (split in two exact
  // 16-bit halves). The primitive target repeats the prop index and the valid flag so that
  // it alone identifies the surface: the CPU can read it back and rebuild the position from
  // the triangle.
  {
    vec3 penumbraPos;
    vec3 penumbraN;
    penumbraSurface(vertexVC, penumbraPos, penumbraN);
    int penumbraPrim = gl_PrimitiveID + PrimitiveIDOffset;
    gl_FragData[0] = vec4(penumbraPos, 1.0);
    gl_FragData[1] = vec4(penumbraN, penumbraPropIndex);
    gl_FragData[2] = vec4(float(penumbraPrim & 65535), float(penumbraPrim >> 16),
                           penumbraPropIndex, 1.0);
  }
