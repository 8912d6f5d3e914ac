#pragma once
// The exit codes of the jelly program (README "The jelly program").
namespace jelly::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitInternalError = 1;  // an unexpected failure (a bug, a full disk)
inline constexpr int kExitBadInput = 2;       // bad scene, option or argument: "error: ..."
// Diverged or solver failure, or with --strict steps that missed the solver's tolerance; the
// output is kept.
inline constexpr int kExitRunFailed = 3;

}  // namespace jelly::cli
