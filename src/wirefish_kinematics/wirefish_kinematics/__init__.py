"""Wire-coupled arc kinematics of the elastic tail, Lighthill body wave and swimming-speed estimate."""
