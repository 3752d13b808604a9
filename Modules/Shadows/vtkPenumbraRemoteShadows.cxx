#include "vtkPenumbraRemoteShadows.h"

// The interface only: vtkPenumbraRayQueries (the ParaView view) implements it.
