// libmorph: morphological filtering of polyhedral meshes. Include this for everything.
#pragma once

#include <morph/error.h>
#include <morph/io.h>
#include <morph/mesh.h>
#include <morph/minkowski_sum.h>
#include <morph/morphology.h>
#include <morph/structuring_element.h>
#include <morph/validate.h>
#include <morph/version.h>
