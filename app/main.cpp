#include "cli/app.hpp"

int main(int argc, char** argv) {
  return gvio::cli::runMain(argc, argv);
}
