"""mount_twin: real-time digital twin of a rigid body on compliant mounts."""
