#pragma once
#include <string>
#include <vector>

namespace transgi::cli {

// Each returns the process exit code; they throw UsageError for bad options
// and std::exception for failures at run time (main reports both in one line).
int run_render(const std::vector<std::string>& args);
int run_compare(const std::vector<std::string>& args);
int run_tonemap(const std::vector<std::string>& args);
int run_bake(const std::vector<std::string>& args);
int run_transfer_study(const std::vector<std::string>& args);
int run_eval(const std::vector<std::string>& args);
int run_bench_pareto(const std::vector<std::string>& args);
int run_bench_frame(const std::vector<std::string>& args);
int run_sun_sweep(const std::vector<std::string>& args);
int run_fly_through(const std::vector<std::string>& args);

}  // namespace transgi::cli
