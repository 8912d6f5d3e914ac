#pragma once
// What the readers of mesh files share (triangle meshes, tet meshes, mesh obstacles): the checks
// before a file is read and the pieces of their messages.
#include <string>

namespace jelly::detail {

// s in double quotes, as messages show a file name.
std::string quoted(const std::string& s);

// The extension of path in lower case, with its dot (".obj"), or "" when it has none.
std::string lower_extension(const std::string& path);

// Throws InputError(field, value, ...) unless path is an existing, readable, regular file of at
// most 1 GiB (a larger one is most likely a mistaken path).
void require_mesh_file(const std::string& path, const std::string& field, const std::string& value);

// Throws InputError(field, value, ...) when the OBJ or ASCII STL file at `path` (`format` "OBJ"
// or "STL"; a binary STL file passes) holds a control character other than tab, line and page
// breaks: a NUL byte in a text file sent assimp's OBJ reader past its buffer (issue 44).
void require_text_mesh(const std::string& path, const std::string& field, const std::string& value,
                       const std::string& format);
// Walks the header and the body of the PLY file at `path` (ASCII or binary) without keeping
// anything, and throws InputError(field, value, ...) for an element count or a list length larger
// than what is left of the file, a negative one, or a property of unknown type (assimp allocates
// what they say before reading the items), and for anything the walk cannot follow: no "ply"
// first line or "end_header" line, another header line, format or version, a list length that
// is no whole number, a body that ends early, a control character in an ASCII file (as
// require_text_mesh), an ASCII element not on a line of its own. Only a file walked to its end goes
// to assimp.
void require_ply_counts_fit(const std::string& path, const std::string& field,
                            const std::string& value);

}  // namespace jelly::detail
