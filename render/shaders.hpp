#pragma once
// GLSL sources of assets/shaders/*.glsl, compiled into the library at configure time (the render
// library does no file I/O). Names: file "lines.geom.glsl" -> kLinesGeom.
namespace gvio::render::shaders {

extern const char* const kPointsVert;
extern const char* const kPointsFrag;
extern const char* const kLinesVert;
extern const char* const kLinesGeom;
extern const char* const kLinesFrag;
extern const char* const kMeshVert;
extern const char* const kMeshFrag;
extern const char* const kVoxelsVert;
extern const char* const kVoxelsFrag;

}  // namespace gvio::render::shaders
