"""Light transport between the proxy's surfaces: form factors, transport with and without the
removed object, radiosity and its propagation, the planner that bounds where the object can
matter, and the patches that send through sub-triangles."""
