"""The team protocol: key expressions, validated messages, the map replica, and the bus helpers
(sessions, inbox, histories, relays)."""
