#pragma once
/// Simulation parameters, presets and `--set key=value` overrides.
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace tender {

/// Which particles of the top row are pinned.
enum class PinMode { Top3, Corners, None };
/// Wind model: superposed sinusoids (tender) or smooth value noise (crumple).
enum class WindKind { Sinusoid, Noise };
/// What a released particle keeps: nothing (zero velocity) or the drag velocity (a toss).
enum class ReleaseMode { ZeroVelocity, DragVelocity };

/// Every parameter of the simulation; presets fill it, `--set` overrides it.
struct SimParams {
  std::string preset = "tender";
  // Sheet
  uint32_t cols = 32;    ///< particles across
  uint32_t rows = 48;    ///< particles down
  float spacing = 0.18f; ///< rest distance between neighbours
  PinMode pins = PinMode::Top3;
  float top_y = 0.0f;      ///< y of the top edge; 0: centred on y = 1, above the floor
  float tilt = 0.0f;       ///< degrees the sheet leans back from hanging (about its top edge): 90 lies flat
  float view_scale = 1.0f; ///< size of the scene the ground covers (1: the tender sheet's; any other: the camera frames
                           ///< the sheet, render::SceneView::sheet_share)
  bool shear = true;       ///< diagonal constraints
  bool bend = true;        ///< skip-one bend constraints (rest 2 x spacing)
  bool tri_bend = false;   ///< bending across each pair of adjacent triangles
  /// Hinges: the signed dihedral angle of every interior edge (the quads' diagonals too), solved in
  /// XPBD with the compliance of bending_rigidity; the quads' other diagonal goes (the sheet folds
  /// along the first)
  bool dihedral = false;
  // Time
  float tick_hz = 120.0f;      ///< fixed ticks per second
  uint32_t substeps = 8;       ///< substeps per tick
  uint32_t iterations = 4;     ///< constraint iterations per substep
  float max_frame_dt = 0.033f; ///< frame dt clamp of the accumulator (s)
  // Forces
  float gravity = 9.81f; ///< magnitude, pointing -Y (units/s^2)
  float damping = 0.99f; ///< Verlet velocity factor per substep
  bool wind = true;      ///< wind on at start
  WindKind wind_kind = WindKind::Sinusoid;
  float wind_strength = 1.0f; ///< multiplier of the wind
  float wind_scale = 1.2f;    ///< wind acceleration at strength 1 (units/s^2)
  // Air (SI units): quadratic pressure drag along each triangle's normal, which also gives lift to a
  // tilted sheet, and skin friction along its plane, per unit mass of the paper
  bool air = false;
  float air_density = 1.2f;      ///< kg/m^3
  float paper_weight = 55.0f;    ///< g/m^2 (thermal receipt paper: 48 to 60)
  float drag_coefficient = 1.5f; ///< of the pressure along the normal
  float skin_friction = 0.02f;   ///< coefficient of the friction along the plane
  // Constraints
  float stiffness = 1.0f;      ///< structural and shear projection stiffness
  float bend_stiffness = 1.0f; ///< bend and tri-bend projection stiffness
  /// Bending rigidity D of the paper (N m) the hinges have: E t^3 / (12 (1 - nu^2))
  float bending_rigidity = 6.4e-5f;
  /// The stretch limit (SimUniforms::limit): no structural edge longer than this x rest after a
  /// substep's projection, unless it tears; 0: off
  float stretch_limit = 0.0f;
  float crease_yield = 0.0f;     ///< degrees a hinge bends past its rest angle before it creases; 0: elastic
  float crease_hardening = 0.0f; ///< the yield a crease adds per radian it moves the rest angle
  float tear_factor = 2.5f;      ///< tear beyond this x rest; 0 disables tearing
  bool tear_structural = true;
  bool tear_shear = false;
  bool tear_bend = true; ///< skip-one and tri-bend constraints
  // Collision
  bool collision = true;
  float cell_size = 0.45f;       ///< spatial hash cell
  float collision_factor = 1.2f; ///< repulsion radius = factor x spacing
  float collision_stiffness = 1.0f;
  /// Contact radius of the penetration-free self-contact (contact.h) as a multiple of spacing; 0: off
  float contact_factor = 0.0f;
  /// With contact and the stretch limit on: the settle stage's sweeps over the structural edges
  /// the contact's cut left longer than the limit (settle_bodies.h); 0: none
  uint32_t contact_settle = 0;
  // Ground
  float floor_y = -6.0f;
  float restitution = 0.2f;
  float friction = 0.3f;
  // Interaction
  ReleaseMode release = ReleaseMode::ZeroVelocity;
  float grab_radius = 0.6f; ///< pick radius around the ray
  float hand_reach = 3.0f;  /// how far around the grab a closing hand reaches (Simulation::squeeze)
  // Performance
  uint32_t threads = 0; ///< CPU solver worker threads; 0 = one per hardware thread (results do not change)
  bool simd = true;     ///< CPU solver SIMD kernels; off runs the plain scalar reference (same results)

  uint32_t particleCount() const { return cols * rows; }
  float tickDt() const { return 1.0f / tick_hz; }
  float substepDt() const { return 1.0f / (tick_hz * float(substeps)); }
  float collisionRadius() const { return collision_factor * spacing; }
  float contactRadius() const { return contact_factor * spacing; }
  /// Factors of the air on a triangle of the rest area spacing^2 / 2 (SimUniforms::air): pressure
  /// and friction, rho C / (2 sigma spacing^2).
  float airPressureFactor() const;
  float airFrictionFactor() const;
  /// The XPBD compliance over dt^2 of a hinge across a grid edge (SimUniforms::crease.compliance): the
  /// discrete-shell stiffness 3 D |e|^2 / (A1 + A2) = 3 D of a grid hinge, per particle mass
  /// (paper_weight x spacing^2: the solver's masses are 1).
  float hingeCompliance() const;
  /// The radius of the ball a closed hand presses the sheet into: the sheet's area in layers a
  /// collision radius thick, packed to kHandPacking.
  float handBallRadius() const;
};

/// How much of a ball crumpled by the hand is paper (layers a collision radius thick).
constexpr float kHandPacking = 0.25f;

/// The range of contact_factor when on (0 is off). Contact is the paper's own thickness around the
/// sheet, so its radius stays under the mesh's spacing:
/// - at sqrt 2 spacings the offsets of particles that share no triangle overlap in the flat sheet,
///   and a sheet at rest moves for ever (a hanging 8 x 8 `crumple` sheet: 0.044 units/s at 1.42,
///   2.9 at 2; 6.4e-5 up to 1.4);
/// - above 0.75 the stretch limit no longer holds in the hand's crumple (1.046 x rest at 1.0),
///   and its pairs grow with the square of the radius (583 ms a tick at 1.0 against 78 at 0.5);
/// - below 0.25 the radius nears rounding: at 1e-33 no step survives the cut, and a denormal one
///   (1e-38) reads as off on one path and on on another.
constexpr float kMinContactFactor = 0.25f;
constexpr float kMaxContactFactor = 0.75f;

/// A built-in preset: its name and its preset file's text (src/core/presets/NAME.json).
struct BuiltinPreset {
  const char* name;
  const char* json;
};
/// The built-in presets, embedded when the programs are built, in the order `--help` lists them.
const std::vector<BuiltinPreset>& builtinPresets();
/// Names of the presets, in the order `--help` lists them.
std::vector<std::string> presetNames();
/// Looks up a preset; nullopt when unknown.
std::optional<SimParams> presetParams(const std::string& name);
/// "unknown preset 'NAME' (one of tender, crumple, ...)": what every program says of an unknown name.
std::string unknownPreset(const std::string& name);

/// What a change of a parameter touches: the running sheet only, the sheet's layout (rebuilt at
/// rest), its topology (the constraint graph: every sheet of a batch shares it; rebuilt too), or the
/// CPU solver (its workers or kernels; the results do not change).
enum class ParamScope : uint8_t { Live, Sheet, Topology, Solver };

/// One documented, settable parameter.
struct ParamInfo {
  std::string key;
  std::string help;
  double lo = 0.0, hi = 0.0; ///< accepted range of a number (lo == hi: not a number)
  bool whole = false;        ///< a whole number (else a float, if a number)
  bool on_off = false;       ///< on/off (else, when not a number, one of some names)
  double least_on = 0.0;     ///< > 0: the number is 0 (off) or at least this
  ParamScope scope = ParamScope::Live;
};
/// True when setting `key` rebuilds the sheet at rest (its scope is Sheet or Topology): the keys
/// that decide the sheet's layout, pins and constraints. (floor_y, which also places a new sheet
/// above the floor, moves the floor under a running one.)
bool rebuildsSheet(const std::string& key);
/// All keys accepted by `--set`.
const std::vector<ParamInfo>& paramKeys();
/// The parameter of a key (its help and range); nullopt when unknown.
std::optional<ParamInfo> paramInfo(const std::string& key);

/// Parses a decimal whole number in [lo, hi] (digits only: no sign, no hex); returns an error.
std::optional<std::string> parseWhole(const std::string& s, uint64_t lo, uint64_t hi, uint64_t& out);

/// The type of a value given as data rather than as `--set` text: a preset file's JSON value or a
/// Python value.
enum class ValueType { Bool, Whole, Number, Text };
/// A typed value spelled as `--set` takes it, by one rule for preset files and Python: true/false
/// only for on/off keys, whole numbers for number keys, other numbers (8.0, 1e3) for the keys that
/// are not whole, text for any key (read as `--set` reads it). `text` is the value as written
/// ("true", "8", "8.0", "on"). Returns "<key>: expected ..., got <text>" when the type does not fit
/// the key, or the unknown key's error.
std::optional<std::string> spellTyped(const std::string& key, ValueType type, const std::string& text,
                                      std::string& out);
/// Largest preset file (every key of one is about 1.5 KB).
constexpr uint64_t kMaxPresetFileBytes = 1u << 20;
/// Limits of the sheet's size: particles across or down, and particles in all.
constexpr uint32_t kMaxSide = 16384;
constexpr uint32_t kMaxParticles = 1u << 24;

/// Applies one `key=value` override; returns an error message on failure.
std::optional<std::string> applyOverride(SimParams& p, const std::string& assignment);
/// Checks the rules between parameters that hold on every machine: a grid of 1 to 2^24
/// particles, the substep limit, a collision radius within the hash cell. Returns the rule broken.
std::optional<std::string> checkRules(const SimParams& p);
/// Checks ranges and cross-parameter rules (radius vs cell) and that the sheet fits this
/// machine's memory on the given backend ("cpu", or a GPU backend: its buffers counted as host
/// memory, as on a CPU device or a GPU with shared memory); returns an error message.
std::optional<std::string> validate(const SimParams& p, const std::string& backend = "gpu");

/// Every key's value in `p`, spelled as `--set` takes it, in the order of paramKeys().
std::vector<std::pair<std::string, std::string>> paramValues(const SimParams& p);
/// `p` as a preset file: a JSON object of "preset" (the name of `p`) and every key, numbers as
/// JSON numbers, on/off as true/false, names as strings (`tender presets --dump NAME`).
std::string presetJson(const SimParams& p);
/// Loads a preset file (--preset-file): a JSON object of keys and values as `--set` takes them
/// (numbers, strings, true/false), optionally "preset": the built-in preset to start from
/// (`tender` when absent). Returns "<path>: <why>" on failure (unreadable, malformed JSON, an
/// unknown key or preset, a bad value).
std::optional<std::string> loadPresetFile(const std::string& path, SimParams& out);
/// Applies a preset file's JSON `text` to `out` (loadPresetFile's rules; `origin` starts its
/// errors): from the built-in preset it names, else from `base` (nullopt: `out` as it is).
std::optional<std::string> applyPresetText(const std::string& text, const std::string& origin,
                                           const std::optional<std::string>& base, SimParams& out);

/// Sizes of the sheet a SimParams describes, counted without building it.
struct SheetCounts {
  uint64_t particles = 0, constraints = 0, triangles = 0;
  uint64_t hinges = 0;       ///< of the constraints, the hinges
  uint64_t hash_buckets = 0; ///< power of two >= 2 x particles
};
/// The counts of buildSheet(p), from the grid alone.
SheetCounts sheetCounts(const SimParams& p);
/// Peak host bytes of a run on a backend ("cpu" or a GPU backend, whose buffers count as host
/// memory): the topology, the solver's arrays, staging and the read-back state.
uint64_t estimateSheetBytes(const SimParams& p, const std::string& backend);
/// Host memory this process may still use: MemAvailable, or half the physical memory.
uint64_t availableMemoryBytes();
/// What a run may plan on of `available` bytes: nine tenths, a tenth left for everything else
/// (a sheet's check, a batch's size).
uint64_t memoryBudget(uint64_t available);

} // namespace tender
