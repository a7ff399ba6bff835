"""``anicov sim``: the physics world playing every robot's ROS 2 base over Zenoh (issue 37, item 1)."""
