#pragma once
// How much memory a run of a given size needs, estimated before it starts, so that a jelly too
// large for the machine is refused with the estimate instead of failing in an allocation.
#include <cstdint>
#include <string>

namespace jelly {

// Particles and springs of an n x n x n cube (core/cube.hpp): n^3 and
// 3 n^2 (n - 1) + 6 n (n - 1)^2 + 4 (n - 1)^3 + 3 n^2 (n - 2) (structural, face and body
// diagonals, bending; 12,876 for n = 10).
std::int64_t cube_particle_count(std::int64_t n);
std::int64_t cube_spring_count(std::int64_t n);

// Bytes of memory a simulation of `particles` particles and `springs` springs needs with the
// named integrator, with a recorder when `recording`. Calibrated on measured peak resident
// sizes (see the .cpp), linear in the counts: an estimate good to a factor of about 1.5 up to
// n = 60, used to refuse runs that cannot fit, not to plan tight ones.
double estimate_memory_bytes(std::int64_t particles, std::int64_t springs,
                             const std::string& integrator, bool recording);

// The memory the operating system can give this process now (MemAvailable plus free swap), or
// a negative value when it cannot be read.
double available_memory_bytes();

// "86.2 GB", "512 MB": bytes for a person.
std::string bytes_text(double bytes);

}  // namespace jelly
