#pragma once
/// @file tools/commands.h
/// @brief Subcommands of the lightoctree front end. Each registers its
/// description and flags on the CLI11 app and returns the function that runs
/// it (addCommand).

#include <CLI/CLI.hpp>
#include <functional>
#include <memory>
#include <string>

namespace lo::tool {

/// Adds the subcommand `name` to `app`, its description and flags
/// registered by `addFlags` on an Options that the function returned keeps.
/// That function runs `run` on them when the command line named this
/// subcommand and returns its exit status, and returns -1 otherwise.
template <class Options>
std::function<int()> addCommand(CLI::App& app, const std::string& name,
                                void (*addFlags)(CLI::App*, Options&), int (*run)(const Options&)) {
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(name);
  addFlags(cmd, *opt);
  return [cmd, opt, run]() -> int { return cmd->parsed() ? run(*opt) : -1; };
}

/// `lightoctree bake SCENE -o OUT.vdb ...`
std::function<int()> addBakeCommand(CLI::App& app);

/// `lightoctree render SCENE LIGHTS.vdb -o IMAGE.{png,exr} ...`
std::function<int()> addRenderCommand(CLI::App& app);

/// `lightoctree lightmap SCENE LIGHTS.vdb -o OUT.{glb,gltf} [--image exr|png] [--preview-unlit] ...`
std::function<int()> addLightmapCommand(CLI::App& app);

/// `lightoctree convert IN.vdb -o OUT.vdb [--depth D] [--vdls K|auto] ...`
std::function<int()> addConvertCommand(CLI::App& app);

/// `lightoctree inspect IN.vdb [--json]`
std::function<int()> addInspectCommand(CLI::App& app);

/// `lightoctree reference SCENE -o REF.exr [--part ...] [--spp N | --time-budget S] ...`
std::function<int()> addReferenceCommand(CLI::App& app);

/// `lightoctree compare TEST REF [--mask M] [--diff D.png] [--json FILE]`
std::function<int()> addCompareCommand(CLI::App& app);

/// `lightoctree sweep SCENE --out DIR [--quick]`
std::function<int()> addSweepCommand(CLI::App& app);

/// `lightoctree view SCENE LIGHTS.vdb | SCENE --progressive [--camera-path F --save-frames D]`
std::function<int()> addViewCommand(CLI::App& app);

}  // namespace lo::tool
