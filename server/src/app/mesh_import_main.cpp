// graspsim-mesh-import: parses one mesh file for graspsim-server in a process of its own, so that a file that
// crashes the parser crashes only this (world/mesh_import.h). Request on stdin, answer on stdout; not for people.
#include "world/mesh_import.h"

int main() { return graspsim::ServeMeshImport(0, 1); }
