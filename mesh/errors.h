// Error types of the geometry API (two-tier errors, see ../shared/STYLE.md).
//
// Geometry functions check their preconditions and throw one of these, with the function name and the problem
// in the message. Byte decoders (codec/) never throw: they return a status. Tools map both to a message and an
// exit code (2 for bad input, 1 for internal failures).
#pragma once

#include <stdexcept>
#include <string>

namespace geomip {

/// Base of every exception thrown by geomip's geometry API.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The input violates a documented precondition: unreadable mesh, NaN coordinates, non-manifold where a
/// manifold is required, an index out of range. The user can fix this by changing the input.
class InvalidInput : public Error {
 public:
  using Error::Error;
};

/// A file could not be opened, read or written for reasons outside the data itself (missing, permissions,
/// disk full).
class IoError : public Error {
 public:
  using Error::Error;
};

/// A numerical method did not converge or produced an invalid result on valid input. This is a bug or a
/// limitation of geomip, never the user's fault.
class SolverFailure : public Error {
 public:
  using Error::Error;
};

}  // namespace geomip
