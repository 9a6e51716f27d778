BEGIN TRANSACTION;
CREATE TABLE errors (
    id INTEGER PRIMARY KEY AUTOINCREMENT, run_id TEXT, match_id TEXT, kind TEXT NOT NULL,
    message TEXT NOT NULL, at REAL NOT NULL);
CREATE TABLE maps (digest TEXT PRIMARY KEY, name TEXT, geometry TEXT NOT NULL);
INSERT INTO "maps" VALUES('53544bb01062945b461cffb9af7199b307a85ed3e340b6402b7da5ed0df660d7','open_room','{"name": "open_room", "merge": false, "boundary": [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]], "obstacles": []}');
CREATE TABLE matches (match_id TEXT PRIMARY KEY, identity TEXT NOT NULL);
INSERT INTO "matches" VALUES('b7a0b62db7668add97a18ece7b677d2778922bc6492b6d44f4386f5ca4242939','{"env": {"body_radius": 0.1, "dt": 0.1, "l_max": 4.0, "l_min": 2.0, "lidar_range": null, "max_cycles": 10, "n_rays": 32, "observation": "state", "reward": "zero_sum", "spawn_margin_steps": 3, "v_evader": 0.5, "v_pursuer": 1.0}, "env_id": "surveillance_v1", "evader": {"model": null, "name": "evader/random", "observation": null, "params": {}}, "map": "53544bb01062945b461cffb9af7199b307a85ed3e340b6402b7da5ed0df660d7", "pursuer": {"model": null, "name": "pursuer/greedy", "observation": null, "params": {}}, "salt": "", "seed": 0, "start": "valid", "version": 1}');
INSERT INTO "matches" VALUES('133eccc29f5f4fb3f3d4668417ae7b609a34af722e7f16afe832f784ec44b623','{"env": {"body_radius": 0.1, "dt": 0.1, "l_max": 4.0, "l_min": 2.0, "lidar_range": null, "max_cycles": 10, "n_rays": 32, "observation": "state", "reward": "zero_sum", "spawn_margin_steps": 3, "v_evader": 0.5, "v_pursuer": 1.0}, "env_id": "surveillance_v1", "evader": {"model": null, "name": "evader/random", "observation": null, "params": {}}, "map": "53544bb01062945b461cffb9af7199b307a85ed3e340b6402b7da5ed0df660d7", "pursuer": {"model": null, "name": "pursuer/greedy", "observation": null, "params": {}}, "salt": "", "seed": 1, "start": "valid", "version": 1}');
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
INSERT INTO "meta" VALUES('schema','1');
CREATE TABLE results (
    match_id TEXT PRIMARY KEY REFERENCES matches,
    status TEXT NOT NULL CHECK (status IN ('ok', 'forfeit', 'error')),
    winner TEXT CHECK (winner IN ('pursuer', 'evader')), cause TEXT, feature TEXT,
    escape_time REAL, steps INTEGER, dt REAL, blame TEXT, error TEXT,
    decide_pursuer REAL, decide_evader REAL, wall_seconds REAL, record TEXT,
    finished REAL NOT NULL);
INSERT INTO "results" VALUES('b7a0b62db7668add97a18ece7b677d2778922bc6492b6d44f4386f5ca4242939','ok','pursuer',NULL,NULL,NULL,10,0.1,NULL,NULL,9.43007005844265195487e-05,8.39466799516230864977e-04,7.17595540045294910669e-02,'{"cause": null, "decide_max": {"evader": 0.008217563008656725, "pursuer": 0.0007578610093332827}, "decide_seconds": {"evader": 0.0008394667995162309, "pursuer": 9.430070058442652e-05}, "dt": 0.1, "escape_time": null, "evader": "evader/random", "feature": null, "map": "open_room", "map_digest": "53544bb01062945b461cffb9af7199b307a85ed3e340b6402b7da5ed0df660d7", "observations": {"evader": {"observation": "state"}, "pursuer": {"observation": "state"}}, "overrides": {"body_radius": 0.1, "dt": 0.1, "l_max": 4.0, "l_min": 2.0, "lidar_range": null, "max_cycles": 10, "n_rays": 32, "observation": "state", "reward": "zero_sum", "spawn_margin_steps": 3, "v_evader": 0.5, "v_pursuer": 1.0}, "pursuer": "pursuer/greedy", "seed": 0, "start": {"evader": [3.9167302876501853, 6.547239187057794], "pursuer": [1.3194593481134143, 6.097578616173997]}, "start_kind": "valid", "steps": 10, "wall_seconds": 0.07175955400452949, "winner": "pursuer"}',1.79588562682619380956e+09);
INSERT INTO "results" VALUES('133eccc29f5f4fb3f3d4668417ae7b609a34af722e7f16afe832f784ec44b623','ok','pursuer',NULL,NULL,NULL,10,0.1,NULL,NULL,1.56014008098281933508e-05,1.28060986753553155467e-05,2.12986799306236207485e-03,'{"cause": null, "decide_max": {"evader": 2.3164000594988465e-05, "pursuer": 3.498300793580711e-05}, "decide_seconds": {"evader": 1.2806098675355316e-05, "pursuer": 1.5601400809828193e-05}, "dt": 0.1, "escape_time": null, "evader": "evader/random", "feature": null, "map": "open_room", "map_digest": "53544bb01062945b461cffb9af7199b307a85ed3e340b6402b7da5ed0df660d7", "observations": {"evader": {"observation": "state"}, "pursuer": {"observation": "state"}}, "overrides": {"body_radius": 0.1, "dt": 0.1, "l_max": 4.0, "l_min": 2.0, "lidar_range": null, "max_cycles": 10, "n_rays": 32, "observation": "state", "reward": "zero_sum", "spawn_margin_steps": 3, "v_evader": 0.5, "v_pursuer": 1.0}, "pursuer": "pursuer/greedy", "seed": 1, "start": {"evader": [6.805870654179883, 2.4128480598958078], "pursuer": [4.403641968182908, 1.058236667192956]}, "start_kind": "valid", "steps": 10, "wall_seconds": 0.002129867993062362, "winner": "pursuer"}',1.79588562682899808881e+09);
CREATE TABLE run_matches (
    run_id TEXT NOT NULL REFERENCES runs, match_id TEXT NOT NULL REFERENCES matches,
    seq INTEGER NOT NULL, map TEXT NOT NULL, variant TEXT NOT NULL, pursuer TEXT NOT NULL,
    evader TEXT NOT NULL, start TEXT NOT NULL, seed INTEGER NOT NULL,
    PRIMARY KEY (run_id, match_id));
INSERT INTO "run_matches" VALUES('6933253d456d535e','b7a0b62db7668add97a18ece7b677d2778922bc6492b6d44f4386f5ca4242939',0,'open_room','','pursuer/greedy','evader/random','valid',0);
INSERT INTO "run_matches" VALUES('6933253d456d535e','133eccc29f5f4fb3f3d4668417ae7b609a34af722e7f16afe832f784ec44b623',1,'open_room','','pursuer/greedy','evader/random','valid',1);
CREATE TABLE runs (
    run_id TEXT PRIMARY KEY, name TEXT NOT NULL, spec TEXT NOT NULL,
    created REAL NOT NULL, updated REAL NOT NULL, status TEXT NOT NULL);
INSERT INTO "runs" VALUES('6933253d456d535e','old_clock','{"description": "", "env": {"max_cycles": 10}, "evaders": [{"label": "evader/random", "model": null, "model_path": null, "name": "evader/random", "observation": null, "params": {}, "role": "evader"}], "maps": [{"digest": "53544bb01062945b461cffb9af7199b307a85ed3e340b6402b7da5ed0df660d7", "label": "open_room", "source": "builtin:open_room"}], "name": "old_clock", "pursuers": [{"label": "pursuer/greedy", "model": null, "model_path": null, "name": "pursuer/greedy", "observation": null, "params": {}, "role": "pursuer"}], "salt": "", "seeds": [0, 1], "starts": ["valid"], "time_limit": 30.0, "time_limit_rule": "decision time per role", "variants": [{"label": "", "overrides": {}, "rho": null}]}',1.79588562646212553976e+09,1.79588562682911920547e+09,'finished');
CREATE INDEX run_matches_seq ON run_matches (run_id, seq);
DELETE FROM "sqlite_sequence";
COMMIT;
