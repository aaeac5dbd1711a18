#pragma once
// The version of the dgtex library a program runs with (the CMake project version, the
// same that find_package(dgtex VERSION) checks at build time), e.g. "0.1.0".
namespace dgtex {

const char* version() noexcept;

}  // namespace dgtex
