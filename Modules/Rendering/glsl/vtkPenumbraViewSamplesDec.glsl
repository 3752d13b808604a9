// Penumbra view samples, declarations (inserted after the mapper's light declarations).
uniform mat4 penumbraVCToRebased;   // view coordinates -> world minus origin (built in double)
uniform vec3 penumbraCameraRebased; // camera position, world minus origin
uniform int penumbraParallel;       // 1 for a parallel projection
uniform vec3 penumbraViewDirection; // direction of projection, world
uniform float penumbraPropIndex;    // index of the prop in the extracted scene geometry
