// (room elements: sources follow)
