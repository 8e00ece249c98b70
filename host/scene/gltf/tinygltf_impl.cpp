// tinygltf's implementation (Debian's libtinygltf-dev is one header), compiled here so that the
// sanitizer and fuzzing builds instrument it with the reader.
#define TINYGLTF_IMPLEMENTATION
#include "scene/gltf/tinygltf.h"
