#pragma once
// Options for the integrators that take any; the explicit methods take none. Which integrator
// reads and writes which member is said by its registry entry (registry.hpp).
#include <string>
#include <string_view>
#include <vector>

#include <jelly/core/errors.hpp>
#include <jelly/core/force.hpp>
#include <jelly/core/json_fwd.hpp>
#include <jelly/core/types.hpp>

// What CHOLMOD is asked to do (solvers/linear/detail/cholmod_solver.hpp does it): the options of
// the integrators that factorize with it, apart from the solver, so that naming them does not bring
// in the sparse matrices.
namespace jelly {

// CHOLMOD's fill-reducing orderings.
enum class CholmodOrdering {
  kAmd,     // approximate minimum degree
  kMetis,   // METIS nested dissection of A + A^T
  kNesdis,  // CHOLMOD's own nested dissection (METIS bisection + constrained minimum degree)
  kBest,    // CHOLMOD's default: AMD, and METIS when AMD gives much fill
};
// "amd", "metis", "nesdis", "best".
const std::vector<EnumName<CholmodOrdering>>& cholmod_orderings();
// "amd", "metis", "nesdis", "best".
std::string_view cholmod_ordering_name(CholmodOrdering ordering);

// How implicit_euler and projective_dynamics use CHOLMOD.
struct CholmodOptions {
  // METIS gives the least fill and the fastest factorization on the seed cube (docs/implicit.md).
  CholmodOrdering ordering = CholmodOrdering::kMetis;
  // Supernodal (BLAS-3) factorization from this many unknowns on; simplicial (no BLAS) below,
  // where BLAS calls, and OpenBLAS waking its threads on a busy machine, cost more than they
  // save (docs/implicit.md, "Measured speed"). 0 = always supernodal; a huge value = always
  // simplicial.
  int supernodal_min_rows = 1000;
};

}  // namespace jelly

// Options of the implicit Euler integrator (docs/implicit.md): each named choice an enum with its
// name table (core/errors.hpp), read from and written to a scene's integrator.options, and
// validated once with the JSON path of the field.
namespace jelly {

// The linear solvers of implicit_euler.
enum class ImplicitLinearSolver {
  kAuto,     // CHOLMOD up to 1000 unknowns, block-Jacobi CG above (the fastest measured there)
  kCholmod,  // CHOLMOD, a numeric factorization every step
  kLdlt,     // Eigen's simplicial LDL^T, a factorization every step
  kCg,       // conjugate gradients with cg_preconditioner
};
// Every implicit_euler linear solver with its name.
const std::vector<EnumName<ImplicitLinearSolver>>& implicit_linear_solvers();

// The preconditioners of implicit_euler's CG.
enum class CgPreconditionerKind {
  kJacobi,   // 3x3 block Jacobi
  kCholmod,  // a CHOLMOD factor of an earlier matrix, refreshed when it stops paying
  // A geometric multigrid V-cycle on lattice bodies (matrix-free CG; block Jacobi elsewhere)
  kMultigrid,
  // Smoothed-aggregation algebraic multigrid on any body (the assembled matrix's CG)
  kAmg,
};
// Every CG preconditioner with its name.
const std::vector<EnumName<CgPreconditionerKind>>& cg_preconditioner_kinds();

// The cycle of cg_preconditioner = amg (docs/implicit.md, "Algebraic multigrid on any body").
enum class AmgCycle {
  kW,  // Chebyshev smoothing of degree 2 on level 0 and 4 below, levels below 1 visited twice
  kV,  // a V-cycle, Chebyshev smoothing of degree 2 on every level
};
const std::vector<EnumName<AmgCycle>>& amg_cycles();  // "w", "v"

// How coulomb terrains enter the step.
enum class ImplicitContactMode {
  kImplicit,   // constraints inside the linear solve, with friction and restitution
  kAfterStep,  // the resolve after the step of the explicit integrators (crushes at large dt)
};
// "implicit", "after_step".
const std::vector<EnumName<ImplicitContactMode>>& implicit_contact_modes();

// The options of implicit_euler (docs/implicit.md).
struct ImplicitEulerOptions {
  // 1 = linearized backward Euler (Baraff & Witkin 1998), one linear solve per step;
  // > 1 = fully nonlinear backward Euler by Newton, at most this many linear solves per step.
  int newton_iterations = 1;
  // Newton stops when |M (v1 - v0) - h f(x0 + h v1, v1)| <= newton_tolerance |h f(x0, v0)|.
  Real newton_tolerance = 1e-8;
  // How compressed springs keep the matrix definite.
  DefinitenessFix definiteness = DefinitenessFix::kClampCompressed;
  // CHOLMOD, LDL^T, CG or chosen by size.
  ImplicitLinearSolver linear_solver = ImplicitLinearSolver::kAuto;
  // For kCg: the lagged CHOLMOD factor is refreshed when its solves cost more than the average
  // since the refresh, when CG needs more than refactor_iterations with it, or when dt changes.
  CgPreconditionerKind cg_preconditioner = CgPreconditionerKind::kJacobi;
  // 1e-5: at dt = 1/60 the solve then moves the particles about 1/1000 of backward Euler's own
  // error (docs/implicit.md, "CG tolerance").
  Real cg_tolerance = 1e-5;           // relative residual |b - A x| / |b|
  int cg_max_iterations = 1000;       // CG stops there and reports a tolerance miss
  int refactor_iterations = 20;       // kCholmod preconditioner: refresh when CG needs more
  AmgCycle amg_cycle = AmgCycle::kW;  // cg_preconditioner = amg: its cycle
  CholmodOrdering ordering = CholmodOrdering::kMetis;  // CHOLMOD's fill-reducing ordering
  // Contact inside the solve or after the step.
  ImplicitContactMode contact = ImplicitContactMode::kImplicit;
  // kImplicit: at most this many linear solves per step while the active set changes.
  int contact_iterations = 10;
  // kImplicit with the matrix-free CG: when > cg_tolerance, each solve of a step with contacts
  // first runs CG only to this relative residual, enough to see whether the contacts' set
  // changes; only a solve that keeps the set is finished to cg_tolerance (and its impulses and
  // friction taken from there). Fewer CG iterations when the set changes often; the jelly
  // ends about as far from an unscreened run as cg_tolerance's own error (docs/implicit.md,
  // "Screening the contacts' set"). 0 = off.
  Real contact_screening_tolerance = 1e-3;

  // Throws InputError "<prefix><field> = <value> is invalid: <allowed>" for the first invalid
  // field (prefix e.g. "integrator.options.").
  void validate(const std::string& prefix) const;
  // The scene's integrator.options of implicit_euler; validated with the fields' JSON path.
  static ImplicitEulerOptions read(JsonFields& fields);
  Json to_json() const;  // the integrator's "options" object that read() reads back
};

}  // namespace jelly

// Options of the adaptive SUNDIALS ARKODE integrators (arkode_erk, arkode_dirk; docs/arkode.md).
namespace jelly {

// How arkode_dirk solves its Newton systems (docs/arkode.md, "The Newton systems").
enum class ArkodeLinearSolver {
  kAuto,    // the fastest in every measurement of docs/arkode.md: kCg
  kCg,      // Schur reduction solved matrix-free by block-Jacobi preconditioned CG
  kJacobi,  // the Newton matrix's 3x3 block diagonal alone (a modified Newton)
  kGmres,   // SUNDIALS' SPGMR on the 6N system, block-Jacobi preconditioned
  kSchur,   // Schur reduction factorized by CHOLMOD at each setup
  kKlu,     // SUNDIALS' KLU on the 6N Jacobian (to check the others)
};
// Every arkode_dirk linear solver with its name.
const std::vector<EnumName<ArkodeLinearSolver>>& arkode_linear_solvers();

// The ARKODE Butcher tables with an embedding (an error estimate), by the names ARKODE gives
// them; the value is ARKODE's table id. Explicit ones for arkode_erk, diagonally implicit ones
// for arkode_dirk.
const std::vector<EnumName<int>>& arkode_erk_methods();
const std::vector<EnumName<int>>& arkode_dirk_methods();  // ARKODE's DIRK tables by name

// The options of arkode_erk and arkode_dirk (docs/arkode.md).
struct ArkodeOptions {
  Real rtol = 1e-6;  // relative tolerance of the local error test, in (0, 1)
  Real atol = 1e-8;  // absolute tolerance (m and m/s), > 0
  // A name of arkode_erk_methods() or arkode_dirk_methods() (which depends on the integrator:
  // "ARKODE_DORMAND_PRINCE_7_4_5" for arkode_erk, "ARKODE_ARK548L2SA_DIRK_8_4_5" for
  // arkode_dirk); empty = that default.
  std::string method;
  Real max_step = 0;  // s, largest internal step; 0 = the contact interval dt
  ArkodeLinearSolver linear_solver = ArkodeLinearSolver::kAuto;  // arkode_dirk only
  long max_steps = 100000;  // internal steps per contact interval, > 0

  // Throws InputError "<prefix><field> = <value> is invalid: ..." for the first invalid field
  // (prefix e.g. "integrator.options."). The method name is checked by the integrator using it
  // (arkode_method_id).
  void validate(const std::string& prefix) const;
  // The scene's integrator.options of arkode_erk and arkode_dirk, validated with their paths.
  static ArkodeOptions read(JsonFields& fields);
  Json to_json() const;  // the integrator's "options" object that read() reads back
};

// The ARKODE table id of `method` in `table` (empty: `default_method`); throws InputError naming
// integrator.options.method with the table's names for another name.
int arkode_method_id(const std::vector<EnumName<int>>& table, const std::string& method,
                     const std::string& default_method);

}  // namespace jelly

// Options of the projective dynamics integrator (docs/realtime.md): each named choice an enum
// with its name table (core/errors.hpp), as implicit_euler's.
namespace jelly {

// How coulomb terrains enter a step of the position-based integrators (projective_dynamics,
// xpbd).
enum class PositionContactMode {
  kProjection,  // inside the step: particles kept on the surface, Coulomb friction
  kAfterStep,   // the explicit integrators' resolve after the step
};
// "projection", "after_step".
const std::vector<EnumName<PositionContactMode>>& position_contact_modes();

// The options of projective_dynamics (docs/realtime.md).
struct ProjectiveDynamicsOptions {
  // Local/global iterations per step (one force evaluation and one prefactored solve each).
  int iterations = 10;
  // > 0: stop earlier once the residual |f - M (v1 - v0) / h| has dropped to this fraction of
  // the residual of the step's first iterate; 0: always run `iterations`.
  Real tolerance = 0;
  // Chebyshev semi-iterative acceleration (Wang 2015) of the iterations.
  bool chebyshev = false;
  // Spectral radius of the plain iteration, in [0, 1); 0 = measured during the first step.
  Real chebyshev_rho = 0;
  // Under-relaxation gamma of the accelerated update, in (0, 1].
  Real chebyshev_gamma = 0.9;
  // Plain iterations of each step before the acceleration starts (Wang's S).
  int chebyshev_delay = 2;
  // How coulomb terrains enter the step: kProjection (inside the iterations: contact particles
  // kept on the surface, their inward residual taken by the contact, Coulomb friction) or
  // kAfterStep (the explicit integrators' resolve after the step).
  PositionContactMode contact = PositionContactMode::kProjection;
  // Fill-reducing ordering of the CHOLMOD factor.
  CholmodOrdering ordering = CholmodOrdering::kMetis;

  // Throws InputError "<prefix><field> = <value> is invalid: <allowed>" for the first invalid
  // field (prefix e.g. "integrator.options.").
  void validate(const std::string& prefix = "integrator.options.") const;
  // The scene's integrator.options of projective_dynamics; validated with the fields' JSON path.
  static ProjectiveDynamicsOptions read(JsonFields& fields);
  Json to_json() const;  // the integrator's "options" object that read() reads back
};

}  // namespace jelly

// Options of the XPBD integrator (docs/realtime.md).
namespace jelly {

// How a sweep visits the springs.
enum class XpbdSweep {
  kJacobi,       // every spring from the same positions, mass split between a particle's springs:
                 // symmetric, momentum-conserving, the same for any thread count (the default)
  kGaussSeidel,  // one after the other in the model's order (the original scheme: a correction
                 // travels up the lattice within a sweep, but the order breaks symmetry and
                 // angular momentum; one thread)
};
const std::vector<EnumName<XpbdSweep>>& xpbd_sweeps();  // "jacobi", "gauss_seidel"

// The options of xpbd (docs/realtime.md).
struct XpbdOptions {
  // Substeps per step (Macklin et al. 2019: many small steps of one iteration each beat few
  // steps of many iterations). Three with two Jacobi sweeps each hold the seed jelly's landing
  // at 1/60 s; one substep of two did not (docs/realtime.md, "Defaults").
  int substeps = 3;
  // Sweeps over the springs (and contacts) per substep.
  int iterations = 2;
  // How a sweep visits the springs (names: xpbd_sweeps()).
  XpbdSweep sweep = XpbdSweep::kJacobi;
  // How coulomb terrains enter the step: kProjection (position constraints with friction in
  // every sweep, restitution after each substep) or kAfterStep (the explicit integrators'
  // resolve after the step). Names: position_contact_modes().
  PositionContactMode contact = PositionContactMode::kProjection;

  // Throws InputError "<prefix><field> = <value> is invalid: <allowed>" for the first invalid
  // field (prefix e.g. "integrator.options.").
  void validate(const std::string& prefix = "integrator.options.") const;
  // The scene's integrator.options of xpbd; validated with the fields' JSON path.
  static XpbdOptions read(JsonFields& fields);
  Json to_json() const;  // the integrator's "options" object that read() reads back
};

}  // namespace jelly

// Options of the vertex block descent integrator (docs/realtime.md).
namespace jelly {

// The options of vbd (docs/realtime.md).
struct VbdOptions {
  // Sweeps over all colours per step (each vertex one 3x3 Newton step per sweep).
  int iterations = 10;
  // Chebyshev semi-iterative acceleration (Wang 2015) of the sweeps with this estimate of their
  // spectral radius, in [0, 1); 0 = off.
  Real chebyshev_rho = 0;
  // Rayleigh-type damping of the paper (Chen et al. 2024, eq. 14): per vertex the force
  // -(damping / h) H_i (x_i - x_i^t), H_i its springs' local Hessian; seconds, >= 0. Added to
  // the springs' own dampers (kd), which enter every sweep exactly.
  Real damping = 0;
  // Coulomb terrains inside the sweeps (experimental): a particle below a surface at the step's
  // end has the penalty energy k d^2 / 2 (d its signed distance, < 0), k = contact_hardness
  // m_i / h^2, in its block (gradient and Hessian k n n^T), so that the springs answer the
  // contact within the step; the Simulator's contact after the step then sees no approach, so
  // that restitution and friction are lost (docs/realtime.md). 0 (default) = the Simulator's
  // contact after the step only. In [0, 1e8].
  Real contact_hardness = 0;

  // Throws InputError "<prefix><field> = <value> is invalid: <allowed>" for the first invalid
  // field (prefix e.g. "integrator.options.").
  void validate(const std::string& prefix = "integrator.options.") const;
  // The scene's integrator.options of vbd; validated with the fields' JSON path.
  static VbdOptions read(JsonFields& fields);
  Json to_json() const;  // the integrator's "options" object that read() reads back
};

}  // namespace jelly

namespace jelly {

// The options of every method a scene can name; only the chosen integrator's are used.
struct IntegratorOptions {
  ImplicitEulerOptions implicit;  // implicit_euler
  ArkodeOptions arkode;           // arkode_erk, arkode_dirk
  ProjectiveDynamicsOptions pd;   // projective_dynamics
  XpbdOptions xpbd;               // xpbd
  VbdOptions vbd;                 // vbd
};

}  // namespace jelly
