#pragma once
// How much memory a run of a given size needs, estimated before it starts, so that a jelly too
// large for the machine is refused with the estimate instead of failing in an allocation.
#include <cstdint>
#include <string>

namespace jelly {

// Bytes of memory a simulation of `particles` particles and `springs` springs needs with the
// named integrator (with its default options), with a recorder when `recording`. Calibrated on
// measured peak resident sizes (see the .cpp): linear in the counts but for projective
// dynamics' factor; an estimate within a factor of 2 of the peak (tested per integrator), used
// to refuse runs that cannot fit, not to plan tight ones.
double estimate_memory_bytes(std::int64_t particles, std::int64_t springs,
                             const std::string& integrator, bool recording);

// The memory the operating system can give this process now (MemAvailable plus free swap), or
// a negative value when it cannot be read.
double available_memory_bytes();

// "86.2 GB", "512 MB": bytes for a person.
std::string bytes_text(double bytes);

}  // namespace jelly
