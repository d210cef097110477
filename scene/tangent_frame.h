// Per-vertex shading frames for primitives that do not carry them: the baker's transfer, the
// validator's lit reference and the glTF export all derive them here, so that a normal map is
// decoded in one and the same frame everywhere.
#pragma once

#include <vector>

#include "scene/scene.h"

namespace vt::scene {

// The power of two that brings `positions` to about unit size (1 when there is none): normals
// are taken from cross products of scaled positions, which normalized() would give up on below
// 1e-30 in a model of 1e-16 units (every face read as degenerate, facing +Z). Exact, so that
// ordinary units get the same bits as unscaled.
double unit_scale(const std::vector<Vec3>& positions);

// Area-weighted vertex normals (unit; +Z where a vertex touches only degenerate faces).
std::vector<Vec3> compute_normals(const Primitive& p);

// glTF's rule for a primitive without NORMAL: flat shading. Gives `p` normals, each face's own,
// splitting a vertex (all its attributes copied) where the faces around it do not face the same
// way; faces within a hundredth of a degree share a vertex, so a flat mesh stays as indexed as it
// was. Degenerate faces take a vertex's first normal (+Z where that is all they touch). Any
// tangents are dropped: they were given for the absent normals (glTF: ignored).
void make_flat_normals(Primitive& p);

// Tangents from UV set `uv_set` per vertex (MikkTSpace-like: area-weighted per-face tangents,
// Gram-Schmidt against the normal, handedness from the bitangent sum; glTF: v points down, the
// bitangent points up the image). `normals` has one entry per vertex.
std::vector<Vec4> compute_tangents(const Primitive& p, const std::vector<Vec3>& normals,
                                   int uv_set);

}  // namespace vt::scene
