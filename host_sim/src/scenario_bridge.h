// SPDX-License-Identifier: MIT
// dynaqpc-sim: a scenario file, as the world sees it and as the firmware sees it.
#ifndef DYNAQPC_SIM_SCENARIO_BRIDGE_H
#define DYNAQPC_SIM_SCENARIO_BRIDGE_H

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "robot/robot_config.h"

namespace world {
struct Scenario;
}

namespace dynaqpc {

class Options;

/// A loaded scenario: the world's description and the firmware configuration built from it.
struct ScenarioBundle {
    std::shared_ptr<const world::Scenario> world;
    robot_config_t robot{};
    std::string name;  ///< kept alive for robot.name
    std::string path;
    std::uint32_t sets = 1;       ///< the scenario's protocol
    std::uint32_t episodes = 1;
};

/// Loads `--scenario NAME|FILE`. A bad file throws UsageError "FILE:LINE: problem".
ScenarioBundle load_scenario(const std::string &arg);

/// A warning (empty: none) for Cricket beacons that transmit too seldom for the firmware's fixes:
/// a fix takes ranges from 3 beacons at most the driver's max_age_us old (3 s), and at the
/// scenario's intervals fewer than 3 beacons' ranges are that fresh on average.
std::string beacon_rate_warning(const world::Scenario &sc);

/// Loads `--changed FILE`, the room `base` becomes during a run (`--change-at K`): a scenario
/// whose obstacles alone differ from base's (world::layout_change_problem()). Anything else
/// throws UsageError "--changed: FILE is not a change of BASE: the goal ... differs (only
/// obstacles may change)".
ScenarioBundle load_changed_scenario(const ScenarioBundle &base, const std::string &arg);

/// Declares `--change-at K` (help `change_at_help`: what K counts, K from 1 to `max`) and
/// `--changed FILE` (the changed room), the options load_change_options() reads.
void declare_change_options(Options &o, const std::string &change_at_help, std::uint32_t *change_at,
                            std::uint32_t max, std::string *changed);

/// `--change-at K --changed FILE` of train (unit "episode") and run ("start"): both or neither,
/// K at most `last`; the changed room (load_changed_scenario()), or an empty bundle without them.
ScenarioBundle load_change_options(const Options &o, const ScenarioBundle &base, const std::string &changed,
                                   std::uint32_t change_at, std::uint32_t last, const char *unit);

/// The agent an `--agent` option names (agent/algorithms.h: q, dyna-q, dyna-qpc, ...); another
/// name throws UsageError.
agent_kind_t agent_kind_of(const std::string &name);

/// `--ablate generalise,majority,new-states,expected,stay` as an AGENT_ABLATE_* mask ("" or "none": 0);
/// another word throws UsageError.
uint8_t ablate_mask(const std::string &list);

/// Every algorithm's name, in agent_kind_t order: the choices of an `--agent` option.
std::vector<std::string> agent_kind_names();

/// The same names as one "q, dyna-q, dyna-qpc" string, for help texts and errors.
std::string agent_kind_list();

/// What a command line may change in a scenario's configuration: the variables a command's
/// Options fill in, null where the command has no such option. The agent always applies (the
/// option's default is dyna-qpc); the rest only when their option was given.
struct ConfigOverrides {
    const std::string *agent = nullptr;        ///< --agent
    const std::uint32_t *planning = nullptr;   ///< --planning
    const std::uint32_t *step_cap = nullptr;   ///< --step-cap
    const double *epsilon = nullptr;           ///< --epsilon
    const double *alpha = nullptr;             ///< --alpha: the Q learning rate, real and planning
    const std::string *gamma = nullptr;        ///< --gamma: a discount (the paper's mode) or auto
    const std::string *model = nullptr;        ///< --model: Dyna-QPC's model, relocatable or paper
    const std::string *model_tiles = nullptr;  ///< --model-tiles: the paper's model's tile widths
    const std::string *explore = nullptr;      ///< --explore: egreedy, plan-bonus or act-bonus
    const double *kappa = nullptr;             ///< --kappa: the bonus's scale
};

/// An exploration mode's name (egreedy, plan-bonus, act-bonus: the scenario's `learning explore`
/// and `--explore`) as an agent_explore_t; another name throws UsageError naming `what`.
uint8_t explore_mode_of(const std::string &name, const std::string &what);

/// The choices of an `--explore` option.
std::vector<std::string> explore_mode_names();

/// The model a `--model` option or a scenario's `learning model` names (relocatable, paper);
/// another name throws UsageError.
std::uint8_t agent_model_of(const std::string &name);

/// Applies `v` to `cfg` as the options `o` were given (one place for train, run and dynaqpc-fw).
void apply_overrides(const Options &o, const ConfigOverrides &v, robot_config_t *cfg);

/// The arena as JSON (docs/tools.md): width, height, obstacles, goal, beacons.
std::string arena_json(const world::Scenario &sc);

}  // namespace dynaqpc

#endif  // DYNAQPC_SIM_SCENARIO_BRIDGE_H
