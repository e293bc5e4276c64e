// Placeholder until platform code lands.
