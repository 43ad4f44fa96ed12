// A shared library that is not a Kiln module: it exports no kiln_pass_module.
extern "C" __attribute__((visibility("default"))) int some_other_function() { return 42; }
