// SPDX-License-Identifier: GPL-3.0-or-later
//
// Flamenco 3 job type "Diminished Reality batch": one task per panorama (.blend), each running
// `blender -b FILE -c dimred OPERATION --object NAME ... --out OUTPUT/<file's stem>` on a worker.
//
// Install: copy this file into the `scripts/` folder next to the Flamenco Manager executable and
// restart the Manager; the job type then shows in the Blender add-on's Flamenco panel. Workers
// need Blender 4.2 or newer with the Diminished Reality extension enabled for the user that runs
// the worker, and the .blend files, their panoramas and the output folder on shared storage at
// the paths given here (Flamenco's two-way variables map them per platform).

const OPERATIONS = ["remove", "relocate", "align"];
const QUALITIES = ["draft", "balanced", "final"];

const JOB_TYPE = {
    label: "Diminished Reality batch",
    description: "Remove (or move, or align) real objects in the HDR panoramas of many .blend files, one task per file",
    settings: [
        {
            key: "blendfiles", type: "string", required: true,
            eval: "bpy.data.filepath",
            description: "The .blend files, separated by ';' (each lit by its own panorama)",
        },
        {
            key: "operation", type: "string", required: true, choices: OPERATIONS, default: "remove",
            description: "remove: the objects in order; relocate: move one object; align: fit one proxy to the photograph",
        },
        {
            key: "objects", type: "string", required: true,
            eval: "C.scene.dimred.target.name if C.scene.dimred.target else ''",
            description: "The object names, separated by ';' (removed in this order; one for relocate and align)",
        },
        {
            key: "quality", type: "string", choices: QUALITIES, default: "balanced",
            description: "Accuracy preset: draft, balanced or final",
        },
        {key: "planes", type: "string", default: "", description: "Surfaces to edit, separated by ';' (empty: found)"},
        {key: "align_first", type: "bool", default: false, description: "Fit the proxy to the photograph first"},
        {key: "yaw", type: "float", default: 0.0, description: "relocate: degrees to turn about the probe's vertical"},
        {key: "distance_scale", type: "float", default: 1.0, description: "relocate: factor on the distance from it"},
        {
            key: "output_root", type: "string", subtype: "dir_path", required: true, visible: "submission",
            description: "Folder that receives one subfolder per .blend file (named after the file)",
        },
    ],
};

function compileJob(job) {
    const settings = job.settings;
    const blendfiles = splitList(settings.blendfiles);
    const objects = splitList(settings.objects);
    const operation = settings.operation || "remove";
    if (!blendfiles.length) throw "no .blend file given in 'blendfiles'";
    if (!objects.length) throw "no object given in 'objects'";
    if (OPERATIONS.indexOf(operation) < 0) throw `unknown operation '${operation}': choose ${OPERATIONS.join(", ")}`;
    if (operation !== "remove" && objects.length !== 1) throw `'${operation}' takes one object, not ${objects.length}`;
    if (!settings.output_root) throw "no 'output_root' given";

    const taken = {};
    for (const blendfile of blendfiles) {
        const name = uniqueName(stem(blendfile), taken);
        const task = author.Task(`dimred-${name}`, "blender");
        task.addCommand(author.Command("blender-render", {
            exe: "{blender}",
            exeArgs: "-b",
            argsBefore: [],
            blendfile: blendfile,
            args: ["-c", "dimred"].concat(commandArguments(settings, operation, objects,
                                                            path.join(settings.output_root, name))),
        }));
        job.addTask(task);
    }
}

// The arguments after `-c dimred`: the same as `python -m addon.cli` takes after the .blend.
function commandArguments(settings, operation, objects, out) {
    let args = [operation];
    for (const name of objects) args.push("--object", name);
    args.push("--out", out, "--quality", settings.quality || "balanced");
    for (const plane of splitList(settings.planes)) args.push("--plane", plane);
    if (operation !== "align" && settings.align_first) args.push("--align");
    if (operation === "relocate") {
        args.push("--yaw", String(orDefault(settings.yaw, 0)),
                  "--distance-scale", String(orDefault(settings.distance_scale, 1)));
    }
    return args;
}

function orDefault(value, fallback) {
    return value === undefined || value === null || value === "" ? fallback : value;
}

function splitList(text) {
    return String(text || "").split(";").map((item) => item.trim()).filter((item) => item.length > 0);
}

// The file name without folder and extension, whichever separator the submitting platform uses.
function stem(file) {
    const base = file.split(/[\\/]/).pop();
    const dot = base.lastIndexOf(".");
    return dot > 0 ? base.slice(0, dot) : base;
}

// Two rooms/scene.blend files from different folders must not share an output folder.
function uniqueName(name, taken) {
    let candidate = name;
    for (let n = 2; taken[candidate]; n++) candidate = `${name}-${n}`;
    taken[candidate] = true;
    return candidate;
}
