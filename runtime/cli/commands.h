#pragma once
// Sub-commands of the dgtex executable. Each takes the arguments after its own name
// (argv[0] is the sub-command's name) and returns the process exit code:
// 0 success, 1 runtime failure, 2 bad input (scene, arguments).
namespace dgtex::cli {

int run_command(int argc, char** argv);            // dgtex run SCENE --out DIR
int render_command(int argc, char** argv);         // dgtex render STATE --out DIR
int bench_laplace_command(int argc, char** argv);  // dgtex bench laplace
int bench_shell_command(int argc, char** argv);    // dgtex bench shell
int bench_render_command(int argc, char** argv);   // dgtex bench render
int bench_scenes_command(int argc, char** argv);   // dgtex bench scenes
int bench_scaling_command(int argc, char** argv);  // dgtex bench scaling
int bench_accuracy_command(int argc, char** argv); // dgtex bench accuracy

}  // namespace dgtex::cli
