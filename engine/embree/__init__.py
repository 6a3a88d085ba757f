"""Intel Embree 4 through its own C API: the library (`library`), scenes built on shared
NumPy buffers (`scene`), and ray queries callable from compiled kernels (`rays`)."""
