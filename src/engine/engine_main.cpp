#include "engine/engine_server.h"

int main(int argc, char** argv) { return convoy::engines::engine_main(argc, argv); }
