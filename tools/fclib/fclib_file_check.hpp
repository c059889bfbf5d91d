// Checks an HDF5 file against what FCLib's reader (fclib 3.1, Debian's
// libfclib-dev) will do with it, before FCLib reads it: FCLib exits the process
// when an HDF5 call fails and allocates its buffers from the file's size fields
// without comparing them with the datasets it then reads into them. Every group
// and dataset FCLib opens must be there, of a numeric (or, for texts, one
// fixed-length string) type and of exactly the length FCLib allocates for it;
// sizes must be >= 0 and spacedim 2 or 3 (FCLib divides by it).
#pragma once

#include <string>

namespace nscd_fclib {

enum class FclibKind { Local, Global };

// True if FCLib can read `path` safely; `kind` says which problem it holds. Else
// false with `error` (what is wrong, without the path). HDF5's own error printing
// is turned off. Sizes above `max_length` elements per array are refused.
bool checkFclibFile(const char* path, FclibKind& kind, std::string& error, long max_length);

}  // namespace nscd_fclib
