// Runs a Flamenco 3 job type's compileJob under node with a stand-in for the Manager's `author`
// and `path` modules, and prints the tasks it authored as JSON:
//   node flamenco_standin.js JOB_TYPE.js SETTINGS_JSON
// An error thrown by compileJob is printed as {"error": ...} (the Manager refuses the job then).
"use strict";
const fs = require("fs");
const vm = require("vm");
const nodePath = require("path");

const [file, settingsJson] = process.argv.slice(2);
const tasks = [];
const author = {
    Task(name, type) {
        const task = {name, type, commands: [], dependencies: []};
        return {
            addCommand(command) { task.commands.push(command); },
            addDependency(other) { task.dependencies.push(other.name); },
            get name() { return task.name; },
            _record: task,
        };
    },
    Command(type, parameters) { return {type, parameters}; },
};
// Flamenco's path functions work on slash-separated paths whatever the platform.
const path = {join: nodePath.posix.join, basename: nodePath.posix.basename, dirname: nodePath.posix.dirname};
const job = {settings: JSON.parse(settingsJson), addTask(task) { tasks.push(task._record); }};
const context = vm.createContext({author, path, print: () => {}, console});
vm.runInContext(fs.readFileSync(file, "utf8"), context, {filename: file});
const jobType = vm.runInContext("JOB_TYPE", context);
try {
    vm.runInContext("compileJob", context)(job);
    console.log(JSON.stringify({jobType, tasks}));
} catch (error) {
    console.log(JSON.stringify({jobType, error: String(error)}));
}
