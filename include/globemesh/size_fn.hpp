// globemesh/size_fn.hpp: the one type of a size function in the library.
//
// A size function gives the target edge length, in km, at a point of the unit sphere; it must
// return a finite value > 0 everywhere it is asked. The size field (sizefield.hpp) makes one;
// the coast shaping (coast.hpp) and the mesher (mesher.hpp) take one. Standard library only.
#pragma once

#include <functional>

#include "globemesh/sphere.hpp"

namespace globemesh {

/// Target edge length in km at a unit vector (finite, > 0).
using SizeFn = std::function<double(const Vec3 &)>;

} // namespace globemesh
