// (room loads: sources follow)
