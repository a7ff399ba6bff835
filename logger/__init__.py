"""The logger process: it records a team over the bus into a rerun recording; the recording's schema;
replay."""
