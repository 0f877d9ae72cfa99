"""StrideFix software-in-the-loop simulator: world, walker, sensor and radio models, board emulator."""
