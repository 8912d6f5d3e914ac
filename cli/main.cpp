// jelly: the program (cli/app.cpp parses its command line and runs the commands).
#include "commands.hpp"

int main(int argc, char** argv) { return jelly::cli::run_jelly(argc, argv); }
