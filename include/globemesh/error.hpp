// globemesh/error.hpp: the exceptions the library throws.
//
// Every message says what went wrong, where (file, layer, option) and, where it helps, what to
// do. The CLI prints it as one line prefixed "globemesh:" and maps UsageError to exit status 2,
// every other Error to 1.
#pragma once

#include <stdexcept>
#include <string>

namespace globemesh {

/// Base of every error globemesh throws on purpose.
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// The caller asked for something invalid: a bad option value, a missing required option.
class UsageError : public Error {
public:
    using Error::Error;
};

/// The input data cannot give a mesh: no CRS, empty layer, no ocean in the region, too few points.
class DataError : public Error {
public:
    using Error::Error;
};

/// Reading or writing a file failed: missing, unreadable, unwritable, existing output.
class IoError : public Error {
public:
    using Error::Error;
};

/// The user cancelled through the progress callback (Ctrl-C in the CLI).
class Cancelled : public Error {
public:
    Cancelled() : Error("cancelled") {}
};

} // namespace globemesh
