#pragma once
// Peak resident memory of this process, per configuration: Linux keeps a high-water mark (VmHWM
// in /proc/self/status) that writing "5" to /proc/self/clear_refs resets to the current resident
// size. When the reset is refused, the mark is the process's peak so far (as getrusage's
// ru_maxrss), and reset_peak_memory() says so.
namespace jelly::bench {

// Resets the high-water mark; false when the kernel refused (the peak then keeps growing).
bool reset_peak_memory();
// VmHWM in bytes (getrusage ru_maxrss when /proc cannot be read).
double peak_memory_bytes();

}  // namespace jelly::bench
