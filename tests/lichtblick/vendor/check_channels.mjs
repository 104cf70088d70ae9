// Built by tests/lichtblick/build.sh: do not edit. It bundles @mcap/core (MIT), fzstd (MIT), @protobufjs/base64 (BSD-3-Clause) and parseJsonSchema and parseChannel from @foxglove/studio-base@1.48.0 assets/index.js (MPL-2.0, source: that npm package; see tests/lichtblick/README.md).
var __create = Object.create;
var __defProp = Object.defineProperty;
var __getOwnPropDesc = Object.getOwnPropertyDescriptor;
var __getOwnPropNames = Object.getOwnPropertyNames;
var __getProtoOf = Object.getPrototypeOf;
var __hasOwnProp = Object.prototype.hasOwnProperty;
var __commonJS = (cb, mod) => function __require() {
  try {
    return mod || (0, cb[__getOwnPropNames(cb)[0]])((mod = { exports: {} }).exports, mod), mod.exports;
  } catch (e) {
    throw mod = 0, e;
  }
};
var __copyProps = (to, from, except, desc) => {
  if (from && typeof from === "object" || typeof from === "function") {
    for (let key of __getOwnPropNames(from))
      if (!__hasOwnProp.call(to, key) && key !== except)
        __defProp(to, key, { get: () => from[key], enumerable: !(desc = __getOwnPropDesc(from, key)) || desc.enumerable });
  }
  return to;
};
var __toESM = (mod, isNodeMode, target) => (target = mod != null ? __create(__getProtoOf(mod)) : {}, __copyProps(
  // If the importer is in node compatibility mode or this is not an ESM
  // file that has been converted to a CommonJS file using a Babel-
  // compatible transform (i.e. "__esModule" has not been set), then set
  // "default" to the CommonJS "module.exports" for node compatibility.
  isNodeMode || !mod || !mod.__esModule ? __defProp(target, "default", { value: mod, enumerable: true }) : target,
  mod
));

// node_modules/@foxglove/crc/dist/cjs/src/index.js
var require_src = __commonJS({
  "node_modules/@foxglove/crc/dist/cjs/src/index.js"(exports) {
    "use strict";
    Object.defineProperty(exports, "__esModule", { value: true });
    exports.crc32 = exports.crc32Final = exports.crc32Update = exports.crc32Init = exports.crc32GenerateTables = void 0;
    function crc32GenerateTables({ polynomial, numTables }) {
      const table = new Uint32Array(256 * numTables);
      for (let i = 0; i < 256; i++) {
        let r = i;
        r = (r & 1) * polynomial ^ r >>> 1;
        r = (r & 1) * polynomial ^ r >>> 1;
        r = (r & 1) * polynomial ^ r >>> 1;
        r = (r & 1) * polynomial ^ r >>> 1;
        r = (r & 1) * polynomial ^ r >>> 1;
        r = (r & 1) * polynomial ^ r >>> 1;
        r = (r & 1) * polynomial ^ r >>> 1;
        r = (r & 1) * polynomial ^ r >>> 1;
        table[i] = r;
      }
      for (let i = 256; i < table.length; i++) {
        const value = table[i - 256];
        table[i] = table[value & 255] ^ value >>> 8;
      }
      return table;
    }
    exports.crc32GenerateTables = crc32GenerateTables;
    var CRC32_TABLE = crc32GenerateTables({ polynomial: 3988292384, numTables: 8 });
    function crc32Init3() {
      return ~0;
    }
    exports.crc32Init = crc32Init3;
    function crc32Update3(prev, data) {
      const byteLength = data.byteLength;
      const view = new DataView(data.buffer, data.byteOffset, byteLength);
      let r = prev;
      let offset = 0;
      const toAlign = -view.byteOffset & 3;
      for (; offset < toAlign && offset < byteLength; offset++) {
        r = CRC32_TABLE[(r ^ view.getUint8(offset)) & 255] ^ r >>> 8;
      }
      if (offset === byteLength) {
        return r;
      }
      offset = toAlign;
      let remainingBytes = byteLength - offset;
      for (; remainingBytes >= 8; offset += 8, remainingBytes -= 8) {
        r ^= view.getUint32(offset, true);
        const r2 = view.getUint32(offset + 4, true);
        r = CRC32_TABLE[0 * 256 + (r2 >>> 24 & 255)] ^ CRC32_TABLE[1 * 256 + (r2 >>> 16 & 255)] ^ CRC32_TABLE[2 * 256 + (r2 >>> 8 & 255)] ^ CRC32_TABLE[3 * 256 + (r2 >>> 0 & 255)] ^ CRC32_TABLE[4 * 256 + (r >>> 24 & 255)] ^ CRC32_TABLE[5 * 256 + (r >>> 16 & 255)] ^ CRC32_TABLE[6 * 256 + (r >>> 8 & 255)] ^ CRC32_TABLE[7 * 256 + (r >>> 0 & 255)];
      }
      for (let i = offset; i < byteLength; i++) {
        r = CRC32_TABLE[(r ^ view.getUint8(i)) & 255] ^ r >>> 8;
      }
      return r;
    }
    exports.crc32Update = crc32Update3;
    function crc32Final3(prev) {
      return (prev ^ ~0) >>> 0;
    }
    exports.crc32Final = crc32Final3;
    function crc326(data) {
      return crc32Final3(crc32Update3(crc32Init3(), data));
    }
    exports.crc32 = crc326;
  }
});

// node_modules/heap-js/dist/heap-js.umd.js
var require_heap_js_umd = __commonJS({
  "node_modules/heap-js/dist/heap-js.umd.js"(exports, module) {
    (function(global, factory) {
      typeof exports === "object" && typeof module !== "undefined" ? factory(exports) : typeof define === "function" && define.amd ? define(["exports"], factory) : (global = typeof globalThis !== "undefined" ? globalThis : global || self, factory(global.heap = {}));
    })(exports, (function(exports2) {
      "use strict";
      var __awaiter = function(thisArg, _arguments, P, generator) {
        function adopt(value) {
          return value instanceof P ? value : new P(function(resolve) {
            resolve(value);
          });
        }
        return new (P || (P = Promise))(function(resolve, reject) {
          function fulfilled(value) {
            try {
              step(generator.next(value));
            } catch (e) {
              reject(e);
            }
          }
          function rejected(value) {
            try {
              step(generator["throw"](value));
            } catch (e) {
              reject(e);
            }
          }
          function step(result) {
            result.done ? resolve(result.value) : adopt(result.value).then(fulfilled, rejected);
          }
          step((generator = generator.apply(thisArg, _arguments || [])).next());
        });
      };
      var __generator$1 = function(thisArg, body) {
        var _ = { label: 0, sent: function() {
          if (t[0] & 1) throw t[1];
          return t[1];
        }, trys: [], ops: [] }, f, y, t, g = Object.create((typeof Iterator === "function" ? Iterator : Object).prototype);
        return g.next = verb(0), g["throw"] = verb(1), g["return"] = verb(2), typeof Symbol === "function" && (g[Symbol.iterator] = function() {
          return this;
        }), g;
        function verb(n) {
          return function(v) {
            return step([n, v]);
          };
        }
        function step(op) {
          if (f) throw new TypeError("Generator is already executing.");
          while (g && (g = 0, op[0] && (_ = 0)), _) try {
            if (f = 1, y && (t = op[0] & 2 ? y["return"] : op[0] ? y["throw"] || ((t = y["return"]) && t.call(y), 0) : y.next) && !(t = t.call(y, op[1])).done) return t;
            if (y = 0, t) op = [op[0] & 2, t.value];
            switch (op[0]) {
              case 0:
              case 1:
                t = op;
                break;
              case 4:
                _.label++;
                return { value: op[1], done: false };
              case 5:
                _.label++;
                y = op[1];
                op = [0];
                continue;
              case 7:
                op = _.ops.pop();
                _.trys.pop();
                continue;
              default:
                if (!(t = _.trys, t = t.length > 0 && t[t.length - 1]) && (op[0] === 6 || op[0] === 2)) {
                  _ = 0;
                  continue;
                }
                if (op[0] === 3 && (!t || op[1] > t[0] && op[1] < t[3])) {
                  _.label = op[1];
                  break;
                }
                if (op[0] === 6 && _.label < t[1]) {
                  _.label = t[1];
                  t = op;
                  break;
                }
                if (t && _.label < t[2]) {
                  _.label = t[2];
                  _.ops.push(op);
                  break;
                }
                if (t[2]) _.ops.pop();
                _.trys.pop();
                continue;
            }
            op = body.call(thisArg, _);
          } catch (e) {
            op = [6, e];
            y = 0;
          } finally {
            f = t = 0;
          }
          if (op[0] & 5) throw op[1];
          return { value: op[0] ? op[1] : void 0, done: true };
        }
      };
      var __read$1 = function(o, n) {
        var m = typeof Symbol === "function" && o[Symbol.iterator];
        if (!m) return o;
        var i = m.call(o), r, ar = [], e;
        try {
          while ((n === void 0 || n-- > 0) && !(r = i.next()).done) ar.push(r.value);
        } catch (error) {
          e = { error };
        } finally {
          try {
            if (r && !r.done && (m = i["return"])) m.call(i);
          } finally {
            if (e) throw e.error;
          }
        }
        return ar;
      };
      var __spreadArray$1 = function(to, from, pack) {
        if (pack || arguments.length === 2) for (var i = 0, l = from.length, ar; i < l; i++) {
          if (ar || !(i in from)) {
            if (!ar) ar = Array.prototype.slice.call(from, 0, i);
            ar[i] = from[i];
          }
        }
        return to.concat(ar || Array.prototype.slice.call(from));
      };
      var __values = function(o) {
        var s = typeof Symbol === "function" && Symbol.iterator, m = s && o[s], i = 0;
        if (m) return m.call(o);
        if (o && typeof o.length === "number") return {
          next: function() {
            if (o && i >= o.length) o = void 0;
            return { value: o && o[i++], done: !o };
          }
        };
        throw new TypeError(s ? "Object is not iterable." : "Symbol.iterator is not defined.");
      };
      var HeapAsync = (
        /** @class */
        (function() {
          function HeapAsync2(compare) {
            if (compare === void 0) {
              compare = HeapAsync2.minComparator;
            }
            var _this = this;
            this.compare = compare;
            this.heapArray = [];
            this._limit = 0;
            this.offer = this.add;
            this.element = this.peek;
            this.poll = this.pop;
            this._invertedCompare = function(a, b) {
              return _this.compare(a, b).then(function(res) {
                return -1 * res;
              });
            };
          }
          HeapAsync2.getChildrenIndexOf = function(idx) {
            return [idx * 2 + 1, idx * 2 + 2];
          };
          HeapAsync2.getParentIndexOf = function(idx) {
            if (idx <= 0) {
              return -1;
            }
            var whichChildren = idx % 2 ? 1 : 2;
            return Math.floor((idx - whichChildren) / 2);
          };
          HeapAsync2.getSiblingIndexOf = function(idx) {
            if (idx <= 0) {
              return -1;
            }
            var whichChildren = idx % 2 ? 1 : -1;
            return idx + whichChildren;
          };
          HeapAsync2.minComparator = function(a, b) {
            return __awaiter(this, void 0, void 0, function() {
              return __generator$1(this, function(_a) {
                if (a > b) {
                  return [2, 1];
                } else if (a < b) {
                  return [2, -1];
                } else {
                  return [2, 0];
                }
              });
            });
          };
          HeapAsync2.maxComparator = function(a, b) {
            return __awaiter(this, void 0, void 0, function() {
              return __generator$1(this, function(_a) {
                if (b > a) {
                  return [2, 1];
                } else if (b < a) {
                  return [2, -1];
                } else {
                  return [2, 0];
                }
              });
            });
          };
          HeapAsync2.minComparatorNumber = function(a, b) {
            return __awaiter(this, void 0, void 0, function() {
              return __generator$1(this, function(_a) {
                return [2, a - b];
              });
            });
          };
          HeapAsync2.maxComparatorNumber = function(a, b) {
            return __awaiter(this, void 0, void 0, function() {
              return __generator$1(this, function(_a) {
                return [2, b - a];
              });
            });
          };
          HeapAsync2.defaultIsEqual = function(a, b) {
            return __awaiter(this, void 0, void 0, function() {
              return __generator$1(this, function(_a) {
                return [2, a === b];
              });
            });
          };
          HeapAsync2.print = function(heap) {
            function deep(i2) {
              var pi = HeapAsync2.getParentIndexOf(i2);
              return Math.floor(Math.log2(pi + 1));
            }
            function repeat(str, times) {
              var out = "";
              for (; times > 0; --times) {
                out += str;
              }
              return out;
            }
            var node = 0;
            var lines = [];
            var maxLines = deep(heap.length - 1) + 2;
            var maxLength = 0;
            while (node < heap.length) {
              var i = deep(node) + 1;
              if (node === 0) {
                i = 0;
              }
              var nodeText = String(heap.get(node));
              if (nodeText.length > maxLength) {
                maxLength = nodeText.length;
              }
              lines[i] = lines[i] || [];
              lines[i].push(nodeText);
              node += 1;
            }
            return lines.map(function(line, i2) {
              var times = Math.pow(2, maxLines - i2) - 1;
              return repeat(" ", Math.floor(times / 2) * maxLength) + line.map(function(el) {
                var half = (maxLength - el.length) / 2;
                return repeat(" ", Math.ceil(half)) + el + repeat(" ", Math.floor(half));
              }).join(repeat(" ", times * maxLength));
            }).join("\n");
          };
          HeapAsync2.heapify = function(arr, compare) {
            return __awaiter(this, void 0, void 0, function() {
              var heap;
              return __generator$1(this, function(_a) {
                switch (_a.label) {
                  case 0:
                    heap = new HeapAsync2(compare);
                    heap.heapArray = arr;
                    return [4, heap.init()];
                  case 1:
                    _a.sent();
                    return [2, heap];
                }
              });
            });
          };
          HeapAsync2.heappop = function(heapArr, compare) {
            var heap = new HeapAsync2(compare);
            heap.heapArray = heapArr;
            return heap.pop();
          };
          HeapAsync2.heappush = function(heapArr, item, compare) {
            return __awaiter(this, void 0, void 0, function() {
              var heap;
              return __generator$1(this, function(_a) {
                switch (_a.label) {
                  case 0:
                    heap = new HeapAsync2(compare);
                    heap.heapArray = heapArr;
                    return [4, heap.push(item)];
                  case 1:
                    _a.sent();
                    return [
                      2
                      /*return*/
                    ];
                }
              });
            });
          };
          HeapAsync2.heappushpop = function(heapArr, item, compare) {
            var heap = new HeapAsync2(compare);
            heap.heapArray = heapArr;
            return heap.pushpop(item);
          };
          HeapAsync2.heapreplace = function(heapArr, item, compare) {
            var heap = new HeapAsync2(compare);
            heap.heapArray = heapArr;
            return heap.replace(item);
          };
          HeapAsync2.heaptop = function(heapArr, n, compare) {
            if (n === void 0) {
              n = 1;
            }
            var heap = new HeapAsync2(compare);
            heap.heapArray = heapArr;
            return heap.top(n);
          };
          HeapAsync2.heapbottom = function(heapArr, n, compare) {
            if (n === void 0) {
              n = 1;
            }
            var heap = new HeapAsync2(compare);
            heap.heapArray = heapArr;
            return heap.bottom(n);
          };
          HeapAsync2.nlargest = function(n, iterable, compare) {
            return __awaiter(this, void 0, void 0, function() {
              var heap;
              return __generator$1(this, function(_a) {
                switch (_a.label) {
                  case 0:
                    heap = new HeapAsync2(compare);
                    heap.heapArray = __spreadArray$1([], __read$1(iterable), false);
                    return [4, heap.init()];
                  case 1:
                    _a.sent();
                    return [2, heap.top(n)];
                }
              });
            });
          };
          HeapAsync2.nsmallest = function(n, iterable, compare) {
            return __awaiter(this, void 0, void 0, function() {
              var heap;
              return __generator$1(this, function(_a) {
                switch (_a.label) {
                  case 0:
                    heap = new HeapAsync2(compare);
                    heap.heapArray = __spreadArray$1([], __read$1(iterable), false);
                    return [4, heap.init()];
                  case 1:
                    _a.sent();
                    return [2, heap.bottom(n)];
                }
              });
            });
          };
          HeapAsync2.prototype.add = function(element) {
            return __awaiter(this, void 0, void 0, function() {
              return __generator$1(this, function(_a) {
                switch (_a.label) {
                  case 0:
                    return [4, this._sortNodeUp(this.heapArray.push(element) - 1)];
                  case 1:
                    _a.sent();
                    this._applyLimit();
                    return [2, true];
                }
              });
            });
          };
          HeapAsync2.prototype.addAll = function(elements) {
            return __awaiter(this, void 0, void 0, function() {
              var i, l;
              var _a;
              return __generator$1(this, function(_b) {
                switch (_b.label) {
                  case 0:
                    i = this.length;
                    (_a = this.heapArray).push.apply(_a, __spreadArray$1([], __read$1(elements), false));
                    l = this.length;
                    _b.label = 1;
                  case 1:
                    if (!(i < l)) return [3, 4];
                    return [4, this._sortNodeUp(i)];
                  case 2:
                    _b.sent();
                    _b.label = 3;
                  case 3:
                    ++i;
                    return [3, 1];
                  case 4:
                    this._applyLimit();
                    return [2, true];
                }
              });
            });
          };
          HeapAsync2.prototype.bottom = function() {
            return __awaiter(this, arguments, void 0, function(n) {
              if (n === void 0) {
                n = 1;
              }
              return __generator$1(this, function(_a) {
                if (this.heapArray.length === 0 || n <= 0) {
                  return [2, []];
                } else if (this.heapArray.length === 1) {
                  return [2, [this.heapArray[0]]];
                } else if (n >= this.heapArray.length) {
                  return [2, __spreadArray$1([], __read$1(this.heapArray), false)];
                } else {
                  return [2, this._bottomN_push(~~n)];
                }
              });
            });
          };
          HeapAsync2.prototype.check = function() {
            return __awaiter(this, void 0, void 0, function() {
              var j, el, children, children_1, children_1_1, ch, e_1_1;
              var e_1, _a;
              return __generator$1(this, function(_b) {
                switch (_b.label) {
                  case 0:
                    j = 0;
                    _b.label = 1;
                  case 1:
                    if (!(j < this.heapArray.length)) return [3, 10];
                    el = this.heapArray[j];
                    children = this.getChildrenOf(j);
                    _b.label = 2;
                  case 2:
                    _b.trys.push([2, 7, 8, 9]);
                    children_1 = (e_1 = void 0, __values(children)), children_1_1 = children_1.next();
                    _b.label = 3;
                  case 3:
                    if (!!children_1_1.done) return [3, 6];
                    ch = children_1_1.value;
                    return [4, this.compare(el, ch)];
                  case 4:
                    if (_b.sent() > 0) {
                      return [2, el];
                    }
                    _b.label = 5;
                  case 5:
                    children_1_1 = children_1.next();
                    return [3, 3];
                  case 6:
                    return [3, 9];
                  case 7:
                    e_1_1 = _b.sent();
                    e_1 = { error: e_1_1 };
                    return [3, 9];
                  case 8:
                    try {
                      if (children_1_1 && !children_1_1.done && (_a = children_1.return)) _a.call(children_1);
                    } finally {
                      if (e_1) throw e_1.error;
                    }
                    return [
                      7
                      /*endfinally*/
                    ];
                  case 9:
                    ++j;
                    return [3, 1];
                  case 10:
                    return [
                      2
                      /*return*/
                    ];
                }
              });
            });
          };
          HeapAsync2.prototype.clear = function() {
            this.heapArray = [];
          };
          HeapAsync2.prototype.clone = function() {
            var cloned = new HeapAsync2(this.comparator());
            cloned.heapArray = this.toArray();
            cloned._limit = this._limit;
            return cloned;
          };
          HeapAsync2.prototype.comparator = function() {
            return this.compare;
          };
          HeapAsync2.prototype.contains = function(o_1) {
            return __awaiter(this, arguments, void 0, function(o, fn) {
              var _a, _b, el, e_2_1;
              var e_2, _c;
              if (fn === void 0) {
                fn = HeapAsync2.defaultIsEqual;
              }
              return __generator$1(this, function(_d) {
                switch (_d.label) {
                  case 0:
                    _d.trys.push([0, 5, 6, 7]);
                    _a = __values(this.heapArray), _b = _a.next();
                    _d.label = 1;
                  case 1:
                    if (!!_b.done) return [3, 4];
                    el = _b.value;
                    return [4, fn(el, o)];
                  case 2:
                    if (_d.sent()) {
                      return [2, true];
                    }
                    _d.label = 3;
                  case 3:
                    _b = _a.next();
                    return [3, 1];
                  case 4:
                    return [3, 7];
                  case 5:
                    e_2_1 = _d.sent();
                    e_2 = { error: e_2_1 };
                    return [3, 7];
                  case 6:
                    try {
                      if (_b && !_b.done && (_c = _a.return)) _c.call(_a);
                    } finally {
                      if (e_2) throw e_2.error;
                    }
                    return [
                      7
                      /*endfinally*/
                    ];
                  case 7:
                    return [2, false];
                }
              });
            });
          };
          HeapAsync2.prototype.init = function(array) {
            return __awaiter(this, void 0, void 0, function() {
              var i;
              return __generator$1(this, function(_a) {
                switch (_a.label) {
                  case 0:
                    if (array) {
                      this.heapArray = __spreadArray$1([], __read$1(array), false);
                    }
                    i = HeapAsync2.getParentIndexOf(this.length - 1);
                    _a.label = 1;
                  case 1:
                    if (!(i >= 0)) return [3, 4];
                    return [4, this._sortNodeDown(i)];
                  case 2:
                    _a.sent();
                    _a.label = 3;
                  case 3:
                    --i;
                    return [3, 1];
                  case 4:
                    this._applyLimit();
                    return [
                      2
                      /*return*/
                    ];
                }
              });
            });
          };
          HeapAsync2.prototype.isEmpty = function() {
            return this.length === 0;
          };
          HeapAsync2.prototype.leafs = function() {
            if (this.heapArray.length === 0) {
              return [];
            }
            var pi = HeapAsync2.getParentIndexOf(this.heapArray.length - 1);
            return this.heapArray.slice(pi + 1);
          };
          Object.defineProperty(HeapAsync2.prototype, "length", {
            /**
             * Length of the heap.
             * @return {Number}
             */
            get: function() {
              return this.heapArray.length;
            },
            enumerable: false,
            configurable: true
          });
          Object.defineProperty(HeapAsync2.prototype, "limit", {
            /**
             * Get length limit of the heap.
             * @return {Number}
             */
            get: function() {
              return this._limit;
            },
            /**
             * Set length limit of the heap.
             * @return {Number}
             */
            set: function(_l) {
              this._limit = ~~_l;
              this._applyLimit();
            },
            enumerable: false,
            configurable: true
          });
          HeapAsync2.prototype.peek = function() {
            return this.heapArray[0];
          };
          HeapAsync2.prototype.pop = function() {
            return __awaiter(this, void 0, void 0, function() {
              var last;
              return __generator$1(this, function(_a) {
                last = this.heapArray.pop();
                if (this.length > 0 && last !== void 0) {
                  return [2, this.replace(last)];
                }
                return [2, last];
              });
            });
          };
          HeapAsync2.prototype.push = function() {
            var elements = [];
            for (var _i = 0; _i < arguments.length; _i++) {
              elements[_i] = arguments[_i];
            }
            return __awaiter(this, void 0, void 0, function() {
              return __generator$1(this, function(_a) {
                if (elements.length < 1) {
                  return [2, false];
                } else if (elements.length === 1) {
                  return [2, this.add(elements[0])];
                } else {
                  return [2, this.addAll(elements)];
                }
              });
            });
          };
          HeapAsync2.prototype.pushpop = function(element) {
            return __awaiter(this, void 0, void 0, function() {
              var _a;
              return __generator$1(this, function(_b) {
                switch (_b.label) {
                  case 0:
                    return [4, this.compare(this.heapArray[0], element)];
                  case 1:
                    if (!(_b.sent() < 0)) return [3, 3];
                    _a = __read$1([this.heapArray[0], element], 2), element = _a[0], this.heapArray[0] = _a[1];
                    return [4, this._sortNodeDown(0)];
                  case 2:
                    _b.sent();
                    _b.label = 3;
                  case 3:
                    return [2, element];
                }
              });
            });
          };
          HeapAsync2.prototype.remove = function(o_1) {
            return __awaiter(this, arguments, void 0, function(o, fn) {
              var queue, idx, children;
              var _this = this;
              if (fn === void 0) {
                fn = HeapAsync2.defaultIsEqual;
              }
              return __generator$1(this, function(_a) {
                switch (_a.label) {
                  case 0:
                    if (!this.heapArray.length)
                      return [2, false];
                    if (!(o === void 0)) return [3, 2];
                    return [4, this.pop()];
                  case 1:
                    _a.sent();
                    return [2, true];
                  case 2:
                    queue = [0];
                    _a.label = 3;
                  case 3:
                    if (!queue.length) return [3, 13];
                    idx = queue.shift();
                    return [4, fn(this.heapArray[idx], o)];
                  case 4:
                    if (!_a.sent()) return [3, 11];
                    if (!(idx === 0)) return [3, 6];
                    return [4, this.pop()];
                  case 5:
                    _a.sent();
                    return [3, 10];
                  case 6:
                    if (!(idx === this.heapArray.length - 1)) return [3, 7];
                    this.heapArray.pop();
                    return [3, 10];
                  case 7:
                    this.heapArray.splice(idx, 1, this.heapArray.pop());
                    return [4, this._sortNodeUp(idx)];
                  case 8:
                    _a.sent();
                    return [4, this._sortNodeDown(idx)];
                  case 9:
                    _a.sent();
                    _a.label = 10;
                  case 10:
                    return [2, true];
                  case 11:
                    children = HeapAsync2.getChildrenIndexOf(idx).filter(function(c) {
                      return c < _this.heapArray.length;
                    });
                    queue.push.apply(queue, __spreadArray$1([], __read$1(children), false));
                    _a.label = 12;
                  case 12:
                    return [3, 3];
                  case 13:
                    return [2, false];
                }
              });
            });
          };
          HeapAsync2.prototype.replace = function(element) {
            return __awaiter(this, void 0, void 0, function() {
              var peek;
              return __generator$1(this, function(_a) {
                switch (_a.label) {
                  case 0:
                    peek = this.heapArray[0];
                    this.heapArray[0] = element;
                    return [4, this._sortNodeDown(0)];
                  case 1:
                    _a.sent();
                    return [2, peek];
                }
              });
            });
          };
          HeapAsync2.prototype.size = function() {
            return this.length;
          };
          HeapAsync2.prototype.top = function() {
            return __awaiter(this, arguments, void 0, function(n) {
              if (n === void 0) {
                n = 1;
              }
              return __generator$1(this, function(_a) {
                if (this.heapArray.length === 0 || n <= 0) {
                  return [2, []];
                } else if (this.heapArray.length === 1 || n === 1) {
                  return [2, [this.heapArray[0]]];
                } else if (n >= this.heapArray.length) {
                  return [2, __spreadArray$1([], __read$1(this.heapArray), false)];
                } else {
                  return [2, this._topN_push(~~n)];
                }
              });
            });
          };
          HeapAsync2.prototype.toArray = function() {
            return __spreadArray$1([], __read$1(this.heapArray), false);
          };
          HeapAsync2.prototype.toString = function() {
            return this.heapArray.toString();
          };
          HeapAsync2.prototype.get = function(i) {
            return this.heapArray[i];
          };
          HeapAsync2.prototype.getChildrenOf = function(idx) {
            var _this = this;
            return HeapAsync2.getChildrenIndexOf(idx).map(function(i) {
              return _this.heapArray[i];
            }).filter(function(e) {
              return e !== void 0;
            });
          };
          HeapAsync2.prototype.getParentOf = function(idx) {
            var pi = HeapAsync2.getParentIndexOf(idx);
            return this.heapArray[pi];
          };
          HeapAsync2.prototype[Symbol.iterator] = function() {
            return __generator$1(this, function(_a) {
              switch (_a.label) {
                case 0:
                  if (!this.length) return [3, 2];
                  return [4, this.pop()];
                case 1:
                  _a.sent();
                  return [3, 0];
                case 2:
                  return [
                    2
                    /*return*/
                  ];
              }
            });
          };
          HeapAsync2.prototype.iterator = function() {
            return this;
          };
          HeapAsync2.prototype._applyLimit = function() {
            if (this._limit && this._limit < this.heapArray.length) {
              var rm = this.heapArray.length - this._limit;
              while (rm) {
                this.heapArray.pop();
                --rm;
              }
            }
          };
          HeapAsync2.prototype._bottomN_push = function(n) {
            return __awaiter(this, void 0, void 0, function() {
              var bottomHeap, startAt, parentStartAt, indices, i, arr, i;
              return __generator$1(this, function(_a) {
                switch (_a.label) {
                  case 0:
                    bottomHeap = new HeapAsync2(this.compare);
                    bottomHeap.limit = n;
                    bottomHeap.heapArray = this.heapArray.slice(-n);
                    return [4, bottomHeap.init()];
                  case 1:
                    _a.sent();
                    startAt = this.heapArray.length - 1 - n;
                    parentStartAt = HeapAsync2.getParentIndexOf(startAt);
                    indices = [];
                    for (i = startAt; i > parentStartAt; --i) {
                      indices.push(i);
                    }
                    arr = this.heapArray;
                    _a.label = 2;
                  case 2:
                    if (!indices.length) return [3, 6];
                    i = indices.shift();
                    return [4, this.compare(arr[i], bottomHeap.peek())];
                  case 3:
                    if (!(_a.sent() > 0)) return [3, 5];
                    return [4, bottomHeap.replace(arr[i])];
                  case 4:
                    _a.sent();
                    if (i % 2) {
                      indices.push(HeapAsync2.getParentIndexOf(i));
                    }
                    _a.label = 5;
                  case 5:
                    return [3, 2];
                  case 6:
                    return [2, bottomHeap.toArray()];
                }
              });
            });
          };
          HeapAsync2.prototype._moveNode = function(j, k) {
            var temp = this.heapArray[j];
            this.heapArray[j] = this.heapArray[k];
            this.heapArray[k] = temp;
          };
          HeapAsync2.prototype._sortNodeDown = function(i) {
            return __awaiter(this, void 0, void 0, function() {
              var length, originalIndex, value, left, right, best, _a;
              return __generator$1(this, function(_b) {
                switch (_b.label) {
                  case 0:
                    length = this.heapArray.length;
                    originalIndex = i;
                    value = this.heapArray[i];
                    left = 2 * i + 1;
                    _b.label = 1;
                  case 1:
                    if (!(left < length)) return [3, 5];
                    right = left + 1;
                    _a = right >= length;
                    if (_a) return [3, 3];
                    return [4, this.compare(this.heapArray[left], this.heapArray[right])];
                  case 2:
                    _a = _b.sent() < 0;
                    _b.label = 3;
                  case 3:
                    best = _a ? left : right;
                    return [4, this.compare(this.heapArray[best], value)];
                  case 4:
                    if (_b.sent() < 0) {
                      this.heapArray[i] = this.heapArray[best];
                      i = best;
                      left = 2 * i + 1;
                    } else
                      return [3, 5];
                    return [3, 1];
                  case 5:
                    if (i !== originalIndex) {
                      this.heapArray[i] = value;
                    }
                    return [
                      2
                      /*return*/
                    ];
                }
              });
            });
          };
          HeapAsync2.prototype._sortNodeUp = function(i) {
            return __awaiter(this, void 0, void 0, function() {
              var value, originalIndex, pi;
              return __generator$1(this, function(_a) {
                switch (_a.label) {
                  case 0:
                    value = this.heapArray[i];
                    originalIndex = i;
                    _a.label = 1;
                  case 1:
                    if (!(i > 0)) return [3, 3];
                    pi = HeapAsync2.getParentIndexOf(i);
                    return [4, this.compare(value, this.heapArray[pi])];
                  case 2:
                    if (_a.sent() < 0) {
                      this.heapArray[i] = this.heapArray[pi];
                      i = pi;
                    } else
                      return [3, 3];
                    return [3, 1];
                  case 3:
                    if (i !== originalIndex) {
                      this.heapArray[i] = value;
                    }
                    return [
                      2
                      /*return*/
                    ];
                }
              });
            });
          };
          HeapAsync2.prototype._topN_push = function(n) {
            return __awaiter(this, void 0, void 0, function() {
              var topHeap, indices, arr, i;
              return __generator$1(this, function(_a) {
                switch (_a.label) {
                  case 0:
                    topHeap = new HeapAsync2(this._invertedCompare);
                    topHeap.limit = n;
                    indices = [0];
                    arr = this.heapArray;
                    _a.label = 1;
                  case 1:
                    if (!indices.length) return [3, 7];
                    i = indices.shift();
                    if (!(i < arr.length)) return [3, 6];
                    if (!(topHeap.length < n)) return [3, 3];
                    return [4, topHeap.push(arr[i])];
                  case 2:
                    _a.sent();
                    indices.push.apply(indices, __spreadArray$1([], __read$1(HeapAsync2.getChildrenIndexOf(i)), false));
                    return [3, 6];
                  case 3:
                    return [4, this.compare(arr[i], topHeap.peek())];
                  case 4:
                    if (!(_a.sent() < 0)) return [3, 6];
                    return [4, topHeap.replace(arr[i])];
                  case 5:
                    _a.sent();
                    indices.push.apply(indices, __spreadArray$1([], __read$1(HeapAsync2.getChildrenIndexOf(i)), false));
                    _a.label = 6;
                  case 6:
                    return [3, 1];
                  case 7:
                    return [2, topHeap.toArray()];
                }
              });
            });
          };
          HeapAsync2.prototype._topN_fill = function(n) {
            return __awaiter(this, void 0, void 0, function() {
              var heapArray, topHeap, branch, indices, i, i;
              return __generator$1(this, function(_a) {
                switch (_a.label) {
                  case 0:
                    heapArray = this.heapArray;
                    topHeap = new HeapAsync2(this._invertedCompare);
                    topHeap.limit = n;
                    topHeap.heapArray = heapArray.slice(0, n);
                    return [4, topHeap.init()];
                  case 1:
                    _a.sent();
                    branch = HeapAsync2.getParentIndexOf(n - 1) + 1;
                    indices = [];
                    for (i = branch; i < n; ++i) {
                      indices.push.apply(indices, __spreadArray$1([], __read$1(HeapAsync2.getChildrenIndexOf(i).filter(function(l) {
                        return l < heapArray.length;
                      })), false));
                    }
                    if ((n - 1) % 2) {
                      indices.push(n);
                    }
                    _a.label = 2;
                  case 2:
                    if (!indices.length) return [3, 6];
                    i = indices.shift();
                    if (!(i < heapArray.length)) return [3, 5];
                    return [4, this.compare(heapArray[i], topHeap.peek())];
                  case 3:
                    if (!(_a.sent() < 0)) return [3, 5];
                    return [4, topHeap.replace(heapArray[i])];
                  case 4:
                    _a.sent();
                    indices.push.apply(indices, __spreadArray$1([], __read$1(HeapAsync2.getChildrenIndexOf(i)), false));
                    _a.label = 5;
                  case 5:
                    return [3, 2];
                  case 6:
                    return [2, topHeap.toArray()];
                }
              });
            });
          };
          HeapAsync2.prototype._topN_heap = function(n) {
            return __awaiter(this, void 0, void 0, function() {
              var topHeap, result, i, _a, _b;
              return __generator$1(this, function(_c) {
                switch (_c.label) {
                  case 0:
                    topHeap = this.clone();
                    result = [];
                    i = 0;
                    _c.label = 1;
                  case 1:
                    if (!(i < n)) return [3, 4];
                    _b = (_a = result).push;
                    return [4, topHeap.pop()];
                  case 2:
                    _b.apply(_a, [_c.sent()]);
                    _c.label = 3;
                  case 3:
                    ++i;
                    return [3, 1];
                  case 4:
                    return [2, result];
                }
              });
            });
          };
          HeapAsync2.prototype._topIdxOf = function(list) {
            return __awaiter(this, void 0, void 0, function() {
              var idx, top, i, comp;
              return __generator$1(this, function(_a) {
                switch (_a.label) {
                  case 0:
                    if (!list.length) {
                      return [2, -1];
                    }
                    idx = 0;
                    top = list[idx];
                    i = 1;
                    _a.label = 1;
                  case 1:
                    if (!(i < list.length)) return [3, 4];
                    return [4, this.compare(list[i], top)];
                  case 2:
                    comp = _a.sent();
                    if (comp < 0) {
                      idx = i;
                      top = list[i];
                    }
                    _a.label = 3;
                  case 3:
                    ++i;
                    return [3, 1];
                  case 4:
                    return [2, idx];
                }
              });
            });
          };
          HeapAsync2.prototype._topOf = function() {
            var list = [];
            for (var _i = 0; _i < arguments.length; _i++) {
              list[_i] = arguments[_i];
            }
            return __awaiter(this, void 0, void 0, function() {
              var heap;
              return __generator$1(this, function(_a) {
                switch (_a.label) {
                  case 0:
                    heap = new HeapAsync2(this.compare);
                    return [4, heap.init(list)];
                  case 1:
                    _a.sent();
                    return [2, heap.peek()];
                }
              });
            });
          };
          return HeapAsync2;
        })()
      );
      var __generator = function(thisArg, body) {
        var _ = { label: 0, sent: function() {
          if (t[0] & 1) throw t[1];
          return t[1];
        }, trys: [], ops: [] }, f, y, t, g = Object.create((typeof Iterator === "function" ? Iterator : Object).prototype);
        return g.next = verb(0), g["throw"] = verb(1), g["return"] = verb(2), typeof Symbol === "function" && (g[Symbol.iterator] = function() {
          return this;
        }), g;
        function verb(n) {
          return function(v) {
            return step([n, v]);
          };
        }
        function step(op) {
          if (f) throw new TypeError("Generator is already executing.");
          while (g && (g = 0, op[0] && (_ = 0)), _) try {
            if (f = 1, y && (t = op[0] & 2 ? y["return"] : op[0] ? y["throw"] || ((t = y["return"]) && t.call(y), 0) : y.next) && !(t = t.call(y, op[1])).done) return t;
            if (y = 0, t) op = [op[0] & 2, t.value];
            switch (op[0]) {
              case 0:
              case 1:
                t = op;
                break;
              case 4:
                _.label++;
                return { value: op[1], done: false };
              case 5:
                _.label++;
                y = op[1];
                op = [0];
                continue;
              case 7:
                op = _.ops.pop();
                _.trys.pop();
                continue;
              default:
                if (!(t = _.trys, t = t.length > 0 && t[t.length - 1]) && (op[0] === 6 || op[0] === 2)) {
                  _ = 0;
                  continue;
                }
                if (op[0] === 3 && (!t || op[1] > t[0] && op[1] < t[3])) {
                  _.label = op[1];
                  break;
                }
                if (op[0] === 6 && _.label < t[1]) {
                  _.label = t[1];
                  t = op;
                  break;
                }
                if (t && _.label < t[2]) {
                  _.label = t[2];
                  _.ops.push(op);
                  break;
                }
                if (t[2]) _.ops.pop();
                _.trys.pop();
                continue;
            }
            op = body.call(thisArg, _);
          } catch (e) {
            op = [6, e];
            y = 0;
          } finally {
            f = t = 0;
          }
          if (op[0] & 5) throw op[1];
          return { value: op[0] ? op[1] : void 0, done: true };
        }
      };
      var __read = function(o, n) {
        var m = typeof Symbol === "function" && o[Symbol.iterator];
        if (!m) return o;
        var i = m.call(o), r, ar = [], e;
        try {
          while ((n === void 0 || n-- > 0) && !(r = i.next()).done) ar.push(r.value);
        } catch (error) {
          e = { error };
        } finally {
          try {
            if (r && !r.done && (m = i["return"])) m.call(i);
          } finally {
            if (e) throw e.error;
          }
        }
        return ar;
      };
      var __spreadArray = function(to, from, pack) {
        if (pack || arguments.length === 2) for (var i = 0, l = from.length, ar; i < l; i++) {
          if (ar || !(i in from)) {
            if (!ar) ar = Array.prototype.slice.call(from, 0, i);
            ar[i] = from[i];
          }
        }
        return to.concat(ar || Array.prototype.slice.call(from));
      };
      var toInt = function(n) {
        return ~~n;
      };
      var Heap2 = (
        /** @class */
        (function() {
          function Heap3(compare) {
            if (compare === void 0) {
              compare = Heap3.minComparator;
            }
            var _this = this;
            this.compare = compare;
            this.heapArray = [];
            this._limit = 0;
            this.offer = this.add;
            this.element = this.peek;
            this.poll = this.pop;
            this.removeAll = this.clear;
            this._invertedCompare = function(a, b) {
              return -1 * _this.compare(a, b);
            };
          }
          Heap3.getChildrenIndexOf = function(idx) {
            return [idx * 2 + 1, idx * 2 + 2];
          };
          Heap3.getParentIndexOf = function(idx) {
            if (idx <= 0) {
              return -1;
            }
            return idx - 1 >> 1;
          };
          Heap3.getSiblingIndexOf = function(idx) {
            if (idx <= 0) {
              return -1;
            }
            var whichChildren = idx % 2 ? 1 : -1;
            return idx + whichChildren;
          };
          Heap3.minComparator = function(a, b) {
            if (a > b) {
              return 1;
            } else if (a < b) {
              return -1;
            } else {
              return 0;
            }
          };
          Heap3.maxComparator = function(a, b) {
            if (b > a) {
              return 1;
            } else if (b < a) {
              return -1;
            } else {
              return 0;
            }
          };
          Heap3.minComparatorNumber = function(a, b) {
            return a - b;
          };
          Heap3.maxComparatorNumber = function(a, b) {
            return b - a;
          };
          Heap3.defaultIsEqual = function(a, b) {
            return a === b;
          };
          Heap3.print = function(heap) {
            function deep(i2) {
              var pi = Heap3.getParentIndexOf(i2);
              return Math.floor(Math.log2(pi + 1));
            }
            function repeat(str, times) {
              var out = "";
              for (; times > 0; --times) {
                out += str;
              }
              return out;
            }
            var node = 0;
            var lines = [];
            var maxLines = deep(heap.length - 1) + 2;
            var maxLength = 0;
            while (node < heap.length) {
              var i = deep(node) + 1;
              if (node === 0) {
                i = 0;
              }
              var nodeText = String(heap.get(node));
              if (nodeText.length > maxLength) {
                maxLength = nodeText.length;
              }
              lines[i] = lines[i] || [];
              lines[i].push(nodeText);
              node += 1;
            }
            return lines.map(function(line, i2) {
              var times = Math.pow(2, maxLines - i2) - 1;
              return repeat(" ", Math.floor(times / 2) * maxLength) + line.map(function(el) {
                var half = (maxLength - el.length) / 2;
                return repeat(" ", Math.ceil(half)) + el + repeat(" ", Math.floor(half));
              }).join(repeat(" ", times * maxLength));
            }).join("\n");
          };
          Heap3.heapify = function(arr, compare) {
            var heap = new Heap3(compare);
            heap.heapArray = arr;
            heap.init();
            return heap;
          };
          Heap3.heappop = function(heapArr, compare) {
            var heap = new Heap3(compare);
            heap.heapArray = heapArr;
            return heap.pop();
          };
          Heap3.heappush = function(heapArr, item, compare) {
            var heap = new Heap3(compare);
            heap.heapArray = heapArr;
            heap.push(item);
          };
          Heap3.heappushpop = function(heapArr, item, compare) {
            var heap = new Heap3(compare);
            heap.heapArray = heapArr;
            return heap.pushpop(item);
          };
          Heap3.heapreplace = function(heapArr, item, compare) {
            var heap = new Heap3(compare);
            heap.heapArray = heapArr;
            return heap.replace(item);
          };
          Heap3.heaptop = function(heapArr, n, compare) {
            if (n === void 0) {
              n = 1;
            }
            var heap = new Heap3(compare);
            heap.heapArray = heapArr;
            return heap.top(n);
          };
          Heap3.heapbottom = function(heapArr, n, compare) {
            if (n === void 0) {
              n = 1;
            }
            var heap = new Heap3(compare);
            heap.heapArray = heapArr;
            return heap.bottom(n);
          };
          Heap3.nlargest = function(n, iterable, compare) {
            var heap = new Heap3(compare);
            heap.heapArray = __spreadArray([], __read(iterable), false);
            heap.init();
            return heap.top(n);
          };
          Heap3.nsmallest = function(n, iterable, compare) {
            var heap = new Heap3(compare);
            heap.heapArray = __spreadArray([], __read(iterable), false);
            heap.init();
            return heap.bottom(n);
          };
          Heap3.prototype.add = function(element) {
            this._sortNodeUp(this.heapArray.push(element) - 1);
            this._applyLimit();
            return true;
          };
          Heap3.prototype.addAll = function(elements) {
            var _a;
            var i = this.length;
            (_a = this.heapArray).push.apply(_a, __spreadArray([], __read(elements), false));
            for (var l = this.length; i < l; ++i) {
              this._sortNodeUp(i);
            }
            this._applyLimit();
            return true;
          };
          Heap3.prototype.bottom = function(n) {
            if (n === void 0) {
              n = 1;
            }
            if (this.heapArray.length === 0 || n <= 0) {
              return [];
            } else if (this.heapArray.length === 1) {
              return [this.heapArray[0]];
            } else if (n >= this.heapArray.length) {
              return __spreadArray([], __read(this.heapArray), false);
            } else {
              return this._bottomN_push(~~n);
            }
          };
          Heap3.prototype.check = function() {
            var _this = this;
            return this.heapArray.find(function(el, j) {
              return !!_this.getChildrenOf(j).find(function(ch) {
                return _this.compare(el, ch) > 0;
              });
            });
          };
          Heap3.prototype.clear = function() {
            this.heapArray = [];
          };
          Heap3.prototype.clone = function() {
            var cloned = new Heap3(this.comparator());
            cloned.heapArray = this.toArray();
            cloned._limit = this._limit;
            return cloned;
          };
          Heap3.prototype.comparator = function() {
            return this.compare;
          };
          Heap3.prototype.contains = function(o, callbackFn) {
            if (callbackFn === void 0) {
              callbackFn = Heap3.defaultIsEqual;
            }
            return this.indexOf(o, callbackFn) !== -1;
          };
          Heap3.prototype.init = function(array) {
            if (array) {
              this.heapArray = __spreadArray([], __read(array), false);
            }
            for (var i = Heap3.getParentIndexOf(this.length - 1); i >= 0; --i) {
              this._sortNodeDown(i);
            }
            this._applyLimit();
          };
          Heap3.prototype.isEmpty = function() {
            return this.length === 0;
          };
          Heap3.prototype.indexOf = function(element, callbackFn) {
            if (callbackFn === void 0) {
              callbackFn = Heap3.defaultIsEqual;
            }
            if (this.heapArray.length === 0) {
              return -1;
            }
            var indexes = [];
            var currentIndex = 0;
            while (currentIndex < this.heapArray.length) {
              var currentElement = this.heapArray[currentIndex];
              if (callbackFn(currentElement, element)) {
                return currentIndex;
              } else if (this.compare(currentElement, element) <= 0) {
                indexes.push.apply(indexes, __spreadArray([], __read(Heap3.getChildrenIndexOf(currentIndex)), false));
              }
              currentIndex = indexes.shift() || this.heapArray.length;
            }
            return -1;
          };
          Heap3.prototype.indexOfEvery = function(element, callbackFn) {
            if (callbackFn === void 0) {
              callbackFn = Heap3.defaultIsEqual;
            }
            if (this.heapArray.length === 0) {
              return [];
            }
            var indexes = [];
            var foundIndexes = [];
            var currentIndex = 0;
            while (currentIndex < this.heapArray.length) {
              var currentElement = this.heapArray[currentIndex];
              if (callbackFn(currentElement, element)) {
                foundIndexes.push(currentIndex);
                indexes.push.apply(indexes, __spreadArray([], __read(Heap3.getChildrenIndexOf(currentIndex)), false));
              } else if (this.compare(currentElement, element) <= 0) {
                indexes.push.apply(indexes, __spreadArray([], __read(Heap3.getChildrenIndexOf(currentIndex)), false));
              }
              currentIndex = indexes.shift() || this.heapArray.length;
            }
            return foundIndexes;
          };
          Heap3.prototype.leafs = function() {
            if (this.heapArray.length === 0) {
              return [];
            }
            var pi = Heap3.getParentIndexOf(this.heapArray.length - 1);
            return this.heapArray.slice(pi + 1);
          };
          Object.defineProperty(Heap3.prototype, "length", {
            /**
             * Length of the heap. Aliases: {@link size}.
             * @return {Number}
             * @see size
             */
            get: function() {
              return this.heapArray.length;
            },
            enumerable: false,
            configurable: true
          });
          Object.defineProperty(Heap3.prototype, "limit", {
            /**
             * Get length limit of the heap.
             * Use {@link setLimit} or {@link limit} to set the limit.
             * @return {Number}
             * @see setLimit
             */
            get: function() {
              return this._limit;
            },
            /**
             * Set length limit of the heap. Same as using {@link setLimit}.
             * @description If the heap is longer than the limit, the needed amount of leafs are removed.
             * @param {Number} _l Limit, defaults to 0 (no limit). Negative, Infinity, or NaN values set the limit to 0.
             * @see setLimit
             */
            set: function(_l) {
              if (_l < 0 || isNaN(_l)) {
                this._limit = 0;
              } else {
                this._limit = ~~_l;
              }
              this._applyLimit();
            },
            enumerable: false,
            configurable: true
          });
          Heap3.prototype.setLimit = function(_l) {
            this.limit = _l;
            if (_l < 0 || isNaN(_l)) {
              return NaN;
            } else {
              return this._limit;
            }
          };
          Heap3.prototype.peek = function() {
            return this.heapArray[0];
          };
          Heap3.prototype.pop = function() {
            var last = this.heapArray.pop();
            if (this.length > 0 && last !== void 0) {
              return this.replace(last);
            }
            return last;
          };
          Heap3.prototype.push = function() {
            var elements = [];
            for (var _i = 0; _i < arguments.length; _i++) {
              elements[_i] = arguments[_i];
            }
            if (elements.length < 1) {
              return false;
            } else if (elements.length === 1) {
              return this.add(elements[0]);
            } else {
              return this.addAll(elements);
            }
          };
          Heap3.prototype.pushpop = function(element) {
            var _a;
            if (this.compare(this.heapArray[0], element) < 0) {
              _a = __read([this.heapArray[0], element], 2), element = _a[0], this.heapArray[0] = _a[1];
              this._sortNodeDown(0);
            }
            return element;
          };
          Heap3.prototype.remove = function(o, callbackFn) {
            var _this = this;
            if (callbackFn === void 0) {
              callbackFn = Heap3.defaultIsEqual;
            }
            if (!this.heapArray.length)
              return false;
            if (o === void 0) {
              this.pop();
              return true;
            }
            var queue = [0];
            while (queue.length) {
              var idx = queue.shift();
              if (callbackFn(this.heapArray[idx], o)) {
                if (idx === 0) {
                  this.pop();
                } else if (idx === this.heapArray.length - 1) {
                  this.heapArray.pop();
                } else {
                  this.heapArray.splice(idx, 1, this.heapArray.pop());
                  this._sortNodeUp(idx);
                  this._sortNodeDown(idx);
                }
                return true;
              } else if (this.compare(this.heapArray[idx], o) <= 0) {
                var children = Heap3.getChildrenIndexOf(idx).filter(function(c) {
                  return c < _this.heapArray.length;
                });
                queue.push.apply(queue, __spreadArray([], __read(children), false));
              }
            }
            return false;
          };
          Heap3.prototype.replace = function(element) {
            var peek = this.heapArray[0];
            this.heapArray[0] = element;
            this._sortNodeDown(0);
            return peek;
          };
          Heap3.prototype.size = function() {
            return this.length;
          };
          Heap3.prototype.top = function(n) {
            if (n === void 0) {
              n = 1;
            }
            if (this.heapArray.length === 0 || n <= 0) {
              return [];
            } else if (this.heapArray.length === 1 || n === 1) {
              return [this.heapArray[0]];
            } else if (n >= this.heapArray.length) {
              return __spreadArray([], __read(this.heapArray), false);
            } else {
              return this._topN_push(~~n);
            }
          };
          Heap3.prototype.toArray = function() {
            return __spreadArray([], __read(this.heapArray), false);
          };
          Heap3.prototype.toString = function() {
            return this.heapArray.toString();
          };
          Heap3.prototype.get = function(i) {
            return this.heapArray[i];
          };
          Heap3.prototype.getChildrenOf = function(idx) {
            var _this = this;
            return Heap3.getChildrenIndexOf(idx).map(function(i) {
              return _this.heapArray[i];
            }).filter(function(e) {
              return e !== void 0;
            });
          };
          Heap3.prototype.getParentOf = function(idx) {
            var pi = Heap3.getParentIndexOf(idx);
            return this.heapArray[pi];
          };
          Heap3.prototype[Symbol.iterator] = function() {
            return __generator(this, function(_a) {
              switch (_a.label) {
                case 0:
                  if (!this.length) return [3, 2];
                  return [4, this.pop()];
                case 1:
                  _a.sent();
                  return [3, 0];
                case 2:
                  return [
                    2
                    /*return*/
                  ];
              }
            });
          };
          Heap3.prototype.iterator = function() {
            return this.toArray();
          };
          Heap3.prototype._applyLimit = function() {
            if (this._limit > 0 && this._limit < this.heapArray.length) {
              var rm = this.heapArray.length - this._limit;
              while (rm) {
                this.heapArray.pop();
                --rm;
              }
            }
          };
          Heap3.prototype._bottomN_push = function(n) {
            var bottomHeap = new Heap3(this.compare);
            bottomHeap.limit = n;
            bottomHeap.heapArray = this.heapArray.slice(-n);
            bottomHeap.init();
            var startAt = this.heapArray.length - 1 - n;
            var parentStartAt = Heap3.getParentIndexOf(startAt);
            var indices = [];
            for (var i = startAt; i > parentStartAt; --i) {
              indices.push(i);
            }
            var arr = this.heapArray;
            while (indices.length) {
              var i = indices.shift();
              if (this.compare(arr[i], bottomHeap.peek()) > 0) {
                bottomHeap.replace(arr[i]);
                if (i % 2) {
                  indices.push(Heap3.getParentIndexOf(i));
                }
              }
            }
            return bottomHeap.toArray();
          };
          Heap3.prototype._moveNode = function(j, k) {
            var temp = this.heapArray[j];
            this.heapArray[j] = this.heapArray[k];
            this.heapArray[k] = temp;
          };
          Heap3.prototype._sortNodeDown = function(i) {
            var length = this.heapArray.length;
            var originalIndex = i;
            var value = this.heapArray[i];
            var left = 2 * i + 1;
            while (left < length) {
              var right = left + 1;
              var best = right >= length || this.compare(this.heapArray[left], this.heapArray[right]) < 0 ? left : right;
              if (this.compare(this.heapArray[best], value) < 0) {
                this.heapArray[i] = this.heapArray[best];
                i = best;
                left = 2 * i + 1;
              } else
                break;
            }
            if (i !== originalIndex) {
              this.heapArray[i] = value;
            }
          };
          Heap3.prototype._sortNodeUp = function(i) {
            var value = this.heapArray[i];
            var originalIndex = i;
            while (i > 0) {
              var pi = Heap3.getParentIndexOf(i);
              if (this.compare(value, this.heapArray[pi]) < 0) {
                this.heapArray[i] = this.heapArray[pi];
                i = pi;
              } else
                break;
            }
            if (i !== originalIndex) {
              this.heapArray[i] = value;
            }
          };
          Heap3.prototype._topN_push = function(n) {
            var topHeap = new Heap3(this._invertedCompare);
            topHeap.limit = n;
            var indices = [0];
            var arr = this.heapArray;
            while (indices.length) {
              var i = indices.shift();
              if (i < arr.length) {
                if (topHeap.length < n) {
                  topHeap.push(arr[i]);
                  indices.push.apply(indices, __spreadArray([], __read(Heap3.getChildrenIndexOf(i)), false));
                } else if (this.compare(arr[i], topHeap.peek()) < 0) {
                  topHeap.replace(arr[i]);
                  indices.push.apply(indices, __spreadArray([], __read(Heap3.getChildrenIndexOf(i)), false));
                }
              }
            }
            return topHeap.toArray();
          };
          Heap3.prototype._topN_fill = function(n) {
            var heapArray = this.heapArray;
            var topHeap = new Heap3(this._invertedCompare);
            topHeap.limit = n;
            topHeap.heapArray = heapArray.slice(0, n);
            topHeap.init();
            var branch = Heap3.getParentIndexOf(n - 1) + 1;
            var indices = [];
            for (var i = branch; i < n; ++i) {
              indices.push.apply(indices, __spreadArray([], __read(Heap3.getChildrenIndexOf(i).filter(function(l) {
                return l < heapArray.length;
              })), false));
            }
            if ((n - 1) % 2) {
              indices.push(n);
            }
            while (indices.length) {
              var i = indices.shift();
              if (i < heapArray.length) {
                if (this.compare(heapArray[i], topHeap.peek()) < 0) {
                  topHeap.replace(heapArray[i]);
                  indices.push.apply(indices, __spreadArray([], __read(Heap3.getChildrenIndexOf(i)), false));
                }
              }
            }
            return topHeap.toArray();
          };
          Heap3.prototype._topN_heap = function(n) {
            var topHeap = this.clone();
            var result = [];
            for (var i = 0; i < n; ++i) {
              result.push(topHeap.pop());
            }
            return result;
          };
          Heap3.prototype._topIdxOf = function(list) {
            if (!list.length) {
              return -1;
            }
            var idx = 0;
            var top = list[idx];
            for (var i = 1; i < list.length; ++i) {
              var comp = this.compare(list[i], top);
              if (comp < 0) {
                idx = i;
                top = list[i];
              }
            }
            return idx;
          };
          Heap3.prototype._topOf = function() {
            var list = [];
            for (var _i = 0; _i < arguments.length; _i++) {
              list[_i] = arguments[_i];
            }
            var heap = new Heap3(this.compare);
            heap.init(list);
            return heap.peek();
          };
          return Heap3;
        })()
      );
      exports2.Heap = Heap2;
      exports2.HeapAsync = HeapAsync;
      exports2.default = Heap2;
      exports2.toInt = toInt;
      Object.defineProperty(exports2, "__esModule", { value: true });
    }));
  }
});

// node_modules/@protobufjs/base64/index.js
var require_base64 = __commonJS({
  "node_modules/@protobufjs/base64/index.js"(exports) {
    "use strict";
    var base642 = exports;
    base642.length = function length(string) {
      var p = string.length;
      if (!p)
        return 0;
      var n = 0;
      while (--p % 4 > 1 && string.charAt(p) === "=")
        ++n;
      return Math.ceil(string.length * 3) / 4 - n;
    };
    var b64 = new Array(64);
    var s64 = new Array(123);
    for (i = 0; i < 64; )
      s64[b64[i] = i < 26 ? i + 65 : i < 52 ? i + 71 : i < 62 ? i - 4 : i - 59 | 43] = i++;
    var i;
    base642.encode = function encode(buffer, start, end) {
      var parts = null, chunk = [];
      var i2 = 0, j = 0, t;
      while (start < end) {
        var b = buffer[start++];
        switch (j) {
          case 0:
            chunk[i2++] = b64[b >> 2];
            t = (b & 3) << 4;
            j = 1;
            break;
          case 1:
            chunk[i2++] = b64[t | b >> 4];
            t = (b & 15) << 2;
            j = 2;
            break;
          case 2:
            chunk[i2++] = b64[t | b >> 6];
            chunk[i2++] = b64[b & 63];
            j = 0;
            break;
        }
        if (i2 > 8191) {
          (parts || (parts = [])).push(String.fromCharCode.apply(String, chunk));
          i2 = 0;
        }
      }
      if (j) {
        chunk[i2++] = b64[t];
        chunk[i2++] = 61;
        if (j === 1)
          chunk[i2++] = 61;
      }
      if (parts) {
        if (i2)
          parts.push(String.fromCharCode.apply(String, chunk.slice(0, i2)));
        return parts.join("");
      }
      return String.fromCharCode.apply(String, chunk.slice(0, i2));
    };
    var invalidEncoding = "invalid encoding";
    base642.decode = function decode(string, buffer, offset) {
      var start = offset;
      var j = 0, t;
      for (var i2 = 0; i2 < string.length; ) {
        var c = string.charCodeAt(i2++);
        if (c === 61 && j > 1)
          break;
        if ((c = s64[c]) === void 0)
          throw Error(invalidEncoding);
        switch (j) {
          case 0:
            t = c;
            j = 1;
            break;
          case 1:
            buffer[offset++] = t << 2 | (c & 48) >> 4;
            t = c;
            j = 2;
            break;
          case 2:
            buffer[offset++] = (t & 15) << 4 | (c & 60) >> 2;
            t = c;
            j = 3;
            break;
          case 3:
            buffer[offset++] = (t & 3) << 6 | c;
            j = 0;
            break;
        }
      }
      if (j === 1)
        throw Error(invalidEncoding);
      return offset - start;
    };
    base642.test = function test(string) {
      return /^(?:[A-Za-z0-9+/]{4})*(?:[A-Za-z0-9+/]{2}==|[A-Za-z0-9+/]{3}=)?$/.test(string);
    };
  }
});

// check_channels.mjs
import { readFileSync } from "node:fs";

// node_modules/@mcap/core/dist/esm/McapIndexedReader.js
var import_crc2 = __toESM(require_src(), 1);
var import_heap_js = __toESM(require_heap_js_umd(), 1);

// node_modules/@mcap/core/dist/esm/getBigUint64.js
var getBigUint64 = typeof DataView.prototype.getBigUint64 === "function" ? DataView.prototype.getBigUint64 : function(offset, littleEndian) {
  const lo = littleEndian === true ? this.getUint32(offset, littleEndian) : this.getUint32(offset + 4, littleEndian);
  const hi = littleEndian === true ? this.getUint32(offset + 4, littleEndian) : this.getUint32(offset, littleEndian);
  return BigInt(hi) << 32n | BigInt(lo);
};

// node_modules/@mcap/core/dist/esm/Reader.js
var textDecoder = new TextDecoder();
var Reader = class {
  #view;
  #viewU8;
  offset;
  constructor(view, offset = 0) {
    this.#view = view;
    this.#viewU8 = new Uint8Array(view.buffer, view.byteOffset, view.byteLength);
    this.offset = offset;
  }
  // Should be ~identical to the constructor, it allows us to reinitialize the reader when
  // the view changes,  without creating a new instance, avoiding allocation / GC overhead
  reset(view, offset = 0) {
    this.#view = view;
    this.#viewU8 = new Uint8Array(view.buffer, view.byteOffset, view.byteLength);
    this.offset = offset;
  }
  bytesRemaining() {
    return this.#viewU8.length - this.offset;
  }
  uint8() {
    const value = this.#view.getUint8(this.offset);
    this.offset += 1;
    return value;
  }
  uint16() {
    const value = this.#view.getUint16(this.offset, true);
    this.offset += 2;
    return value;
  }
  uint32() {
    const value = this.#view.getUint32(this.offset, true);
    this.offset += 4;
    return value;
  }
  uint64() {
    const value = getBigUint64.call(this.#view, this.offset, true);
    this.offset += 8;
    return value;
  }
  string() {
    const length = this.uint32();
    if (length === 0) {
      return "";
    } else if (length > this.bytesRemaining()) {
      throw new Error(`String length ${length} exceeds bounds of buffer`);
    }
    return textDecoder.decode(this.u8ArrayBorrow(length));
  }
  keyValuePairs(readKey, readValue) {
    const length = this.uint32();
    if (this.offset + length > this.#view.byteLength) {
      throw new Error(`Key-value pairs length ${length} exceeds bounds of buffer`);
    }
    const result = [];
    const endOffset = this.offset + length;
    try {
      while (this.offset < endOffset) {
        result.push([readKey(this), readValue(this)]);
      }
    } catch (err2) {
      throw new Error(`Error reading key-value pairs: ${err2.message}`);
    }
    if (this.offset !== endOffset) {
      throw new Error(`Key-value pairs length (${this.offset - endOffset + length}) greater than expected (${length})`);
    }
    return result;
  }
  map(readKey, readValue) {
    const length = this.uint32();
    if (this.offset + length > this.#view.byteLength) {
      throw new Error(`Map length ${length} exceeds bounds of buffer`);
    }
    const result = /* @__PURE__ */ new Map();
    const endOffset = this.offset + length;
    try {
      while (this.offset < endOffset) {
        const key = readKey(this);
        const value = readValue(this);
        const existingValue = result.get(key);
        if (existingValue != void 0) {
          throw new Error(`Duplicate key ${String(key)} (${String(existingValue)} vs ${String(value)})`);
        }
        result.set(key, value);
      }
    } catch (err2) {
      throw new Error(`Error reading map: ${err2.message}`);
    }
    if (this.offset !== endOffset) {
      throw new Error(`Map length (${this.offset - endOffset + length}) greater than expected (${length})`);
    }
    return result;
  }
  // Read a borrowed Uint8Array, useful temp references or borrow semantics
  u8ArrayBorrow(length) {
    const result = this.#viewU8.subarray(this.offset, this.offset + length);
    this.offset += length;
    return result;
  }
  // Read a copied Uint8Array from the underlying buffer, use when you need to keep the data around
  u8ArrayCopy(length) {
    const result = this.#viewU8.slice(this.offset, this.offset + length);
    this.offset += length;
    return result;
  }
};

// node_modules/@mcap/core/dist/esm/parse.js
var import_crc = __toESM(require_src(), 1);

// node_modules/@mcap/core/dist/esm/constants.js
var MCAP_MAGIC = Object.freeze([137, 77, 67, 65, 80, 48, 13, 10]);
var Opcode;
(function(Opcode2) {
  Opcode2[Opcode2["MIN"] = 1] = "MIN";
  Opcode2[Opcode2["HEADER"] = 1] = "HEADER";
  Opcode2[Opcode2["FOOTER"] = 2] = "FOOTER";
  Opcode2[Opcode2["SCHEMA"] = 3] = "SCHEMA";
  Opcode2[Opcode2["CHANNEL"] = 4] = "CHANNEL";
  Opcode2[Opcode2["MESSAGE"] = 5] = "MESSAGE";
  Opcode2[Opcode2["CHUNK"] = 6] = "CHUNK";
  Opcode2[Opcode2["MESSAGE_INDEX"] = 7] = "MESSAGE_INDEX";
  Opcode2[Opcode2["CHUNK_INDEX"] = 8] = "CHUNK_INDEX";
  Opcode2[Opcode2["ATTACHMENT"] = 9] = "ATTACHMENT";
  Opcode2[Opcode2["ATTACHMENT_INDEX"] = 10] = "ATTACHMENT_INDEX";
  Opcode2[Opcode2["STATISTICS"] = 11] = "STATISTICS";
  Opcode2[Opcode2["METADATA"] = 12] = "METADATA";
  Opcode2[Opcode2["METADATA_INDEX"] = 13] = "METADATA_INDEX";
  Opcode2[Opcode2["SUMMARY_OFFSET"] = 14] = "SUMMARY_OFFSET";
  Opcode2[Opcode2["DATA_END"] = 15] = "DATA_END";
  Opcode2[Opcode2["MAX"] = 15] = "MAX";
})(Opcode || (Opcode = {}));

// node_modules/@mcap/core/dist/esm/parse.js
function parseMagic(reader) {
  if (reader.bytesRemaining() < MCAP_MAGIC.length) {
    return void 0;
  }
  const magic = reader.u8ArrayBorrow(MCAP_MAGIC.length);
  if (!MCAP_MAGIC.every((val, i) => val === magic[i])) {
    throw new Error(`Expected MCAP magic '${MCAP_MAGIC.map((val) => val.toString(16).padStart(2, "0")).join(" ")}', found '${Array.from(magic, (_, i) => magic[i].toString(16).padStart(2, "0")).join(" ")}'`);
  }
  return { specVersion: "0" };
}
function parseRecord(reader, validateCrcs = false) {
  const RECORD_HEADER_SIZE = 1 + 8;
  if (reader.bytesRemaining() < RECORD_HEADER_SIZE) {
    return void 0;
  }
  const start = reader.offset;
  const opcode = reader.uint8();
  const recordLength = reader.uint64();
  if (recordLength > Number.MAX_SAFE_INTEGER) {
    throw new Error(`Record content length ${recordLength} is too large`);
  }
  const recordLengthNum = Number(recordLength);
  if (reader.bytesRemaining() < recordLengthNum) {
    reader.offset = start;
    return void 0;
  }
  let result;
  switch (opcode) {
    case Opcode.HEADER:
      result = parseHeader(reader, recordLengthNum);
      break;
    case Opcode.FOOTER:
      result = parseFooter(reader, recordLengthNum);
      break;
    case Opcode.SCHEMA:
      result = parseSchema(reader, recordLengthNum);
      break;
    case Opcode.CHANNEL:
      result = parseChannel(reader, recordLengthNum);
      break;
    case Opcode.MESSAGE:
      result = parseMessage(reader, recordLengthNum);
      break;
    case Opcode.CHUNK:
      result = parseChunk(reader, recordLengthNum);
      break;
    case Opcode.MESSAGE_INDEX:
      result = parseMessageIndex(reader, recordLengthNum);
      break;
    case Opcode.CHUNK_INDEX:
      result = parseChunkIndex(reader, recordLengthNum);
      break;
    case Opcode.ATTACHMENT:
      result = parseAttachment(reader, recordLengthNum, validateCrcs);
      break;
    case Opcode.ATTACHMENT_INDEX:
      result = parseAttachmentIndex(reader, recordLengthNum);
      break;
    case Opcode.STATISTICS:
      result = parseStatistics(reader, recordLengthNum);
      break;
    case Opcode.METADATA:
      result = parseMetadata(reader, recordLengthNum);
      break;
    case Opcode.METADATA_INDEX:
      result = parseMetadataIndex(reader, recordLengthNum);
      break;
    case Opcode.SUMMARY_OFFSET:
      result = parseSummaryOffset(reader, recordLengthNum);
      break;
    case Opcode.DATA_END:
      result = parseDataEnd(reader, recordLengthNum);
      break;
    default:
      result = parseUnknown(reader, recordLengthNum, opcode);
      break;
  }
  reader.offset = start + RECORD_HEADER_SIZE + recordLengthNum;
  return result;
}
function parseUnknown(reader, recordLength, opcode) {
  const data = reader.u8ArrayBorrow(recordLength);
  return {
    type: "Unknown",
    opcode,
    data
  };
}
function parseHeader(reader, recordLength) {
  const startOffset = reader.offset;
  const profile = reader.string();
  const library = reader.string();
  reader.offset = startOffset + recordLength;
  return { type: "Header", profile, library };
}
function parseFooter(reader, recordLength) {
  const startOffset = reader.offset;
  const summaryStart = reader.uint64();
  const summaryOffsetStart = reader.uint64();
  const summaryCrc = reader.uint32();
  reader.offset = startOffset + recordLength;
  return {
    type: "Footer",
    summaryStart,
    summaryOffsetStart,
    summaryCrc
  };
}
function parseSchema(reader, recordLength) {
  const start = reader.offset;
  const id = reader.uint16();
  const name = reader.string();
  const encoding = reader.string();
  const dataLen = reader.uint32();
  const end = reader.offset;
  if (recordLength - (end - start) < dataLen) {
    throw new Error(`Schema data length ${dataLen} exceeds bounds of record`);
  }
  const data = reader.u8ArrayCopy(dataLen);
  reader.offset = start + recordLength;
  return {
    type: "Schema",
    id,
    encoding,
    name,
    data
  };
}
function parseChannel(reader, recordLength) {
  const startOffset = reader.offset;
  const channelId = reader.uint16();
  const schemaId = reader.uint16();
  const topicName = reader.string();
  const messageEncoding = reader.string();
  const metadata = reader.map((r) => r.string(), (r) => r.string());
  reader.offset = startOffset + recordLength;
  return {
    type: "Channel",
    id: channelId,
    schemaId,
    topic: topicName,
    messageEncoding,
    metadata
  };
}
function parseMessage(reader, recordLength) {
  const MESSAGE_PREFIX_SIZE = 2 + 4 + 8 + 8;
  const channelId = reader.uint16();
  const sequence = reader.uint32();
  const logTime = reader.uint64();
  const publishTime = reader.uint64();
  const data = reader.u8ArrayCopy(recordLength - MESSAGE_PREFIX_SIZE);
  return {
    type: "Message",
    channelId,
    sequence,
    logTime,
    publishTime,
    data
  };
}
function parseChunk(reader, recordLength) {
  const start = reader.offset;
  const startTime = reader.uint64();
  const endTime = reader.uint64();
  const uncompressedSize = reader.uint64();
  const uncompressedCrc = reader.uint32();
  const compression = reader.string();
  const recordsByteLength = Number(reader.uint64());
  const end = reader.offset;
  const prefixSize = end - start;
  if (recordsByteLength + prefixSize > recordLength) {
    throw new Error("Chunk records length exceeds remaining record size");
  }
  const records2 = reader.u8ArrayCopy(recordsByteLength);
  reader.offset = start + recordLength;
  return {
    type: "Chunk",
    messageStartTime: startTime,
    messageEndTime: endTime,
    compression,
    uncompressedSize,
    uncompressedCrc,
    records: records2
  };
}
function parseMessageIndex(reader, recordLength) {
  const startOffset = reader.offset;
  const channelId = reader.uint16();
  const records2 = reader.keyValuePairs((r) => r.uint64(), (r) => r.uint64());
  reader.offset = startOffset + recordLength;
  return {
    type: "MessageIndex",
    channelId,
    records: records2
  };
}
function parseChunkIndex(reader, recordLength) {
  const startOffset = reader.offset;
  const messageStartTime = reader.uint64();
  const messageEndTime = reader.uint64();
  const chunkStartOffset = reader.uint64();
  const chunkLength = reader.uint64();
  const messageIndexOffsets = reader.map((r) => r.uint16(), (r) => r.uint64());
  const messageIndexLength = reader.uint64();
  const compression = reader.string();
  const compressedSize = reader.uint64();
  const uncompressedSize = reader.uint64();
  reader.offset = startOffset + recordLength;
  return {
    type: "ChunkIndex",
    messageStartTime,
    messageEndTime,
    chunkStartOffset,
    chunkLength,
    messageIndexOffsets,
    messageIndexLength,
    compression,
    compressedSize,
    uncompressedSize
  };
}
function parseAttachment(reader, recordLength, validateCrcs) {
  const startOffset = reader.offset;
  const logTime = reader.uint64();
  const createTime = reader.uint64();
  const name = reader.string();
  const mediaType = reader.string();
  const dataLen = reader.uint64();
  if (BigInt(reader.offset) + dataLen > Number.MAX_SAFE_INTEGER) {
    throw new Error(`Attachment too large: ${dataLen}`);
  }
  if (reader.offset + Number(dataLen) + 4 > startOffset + recordLength) {
    throw new Error(`Attachment data length ${dataLen} exceeds bounds of record`);
  }
  const data = reader.u8ArrayCopy(Number(dataLen));
  const crcLength = reader.offset - startOffset;
  const expectedCrc = reader.uint32();
  if (validateCrcs && expectedCrc !== 0) {
    reader.offset = startOffset;
    const fullData = reader.u8ArrayBorrow(crcLength);
    const actualCrc = (0, import_crc.crc32)(fullData);
    reader.offset = startOffset + crcLength + 4;
    if (actualCrc !== expectedCrc) {
      throw new Error(`Attachment CRC32 mismatch: expected ${expectedCrc}, actual ${actualCrc}`);
    }
  }
  reader.offset = startOffset + recordLength;
  return {
    type: "Attachment",
    logTime,
    createTime,
    name,
    mediaType,
    data
  };
}
function parseAttachmentIndex(reader, recordLength) {
  const startOffset = reader.offset;
  const offset = reader.uint64();
  const length = reader.uint64();
  const logTime = reader.uint64();
  const createTime = reader.uint64();
  const dataSize = reader.uint64();
  const name = reader.string();
  const mediaType = reader.string();
  reader.offset = startOffset + recordLength;
  return {
    type: "AttachmentIndex",
    offset,
    length,
    logTime,
    createTime,
    dataSize,
    name,
    mediaType
  };
}
function parseStatistics(reader, recordLength) {
  const startOffset = reader.offset;
  const messageCount = reader.uint64();
  const schemaCount = reader.uint16();
  const channelCount = reader.uint32();
  const attachmentCount = reader.uint32();
  const metadataCount = reader.uint32();
  const chunkCount = reader.uint32();
  const messageStartTime = reader.uint64();
  const messageEndTime = reader.uint64();
  const channelMessageCounts = reader.map((r) => r.uint16(), (r) => r.uint64());
  reader.offset = startOffset + recordLength;
  return {
    type: "Statistics",
    messageCount,
    schemaCount,
    channelCount,
    attachmentCount,
    metadataCount,
    chunkCount,
    messageStartTime,
    messageEndTime,
    channelMessageCounts
  };
}
function parseMetadata(reader, recordLength) {
  const startOffset = reader.offset;
  const name = reader.string();
  const metadata = reader.map((r) => r.string(), (r) => r.string());
  reader.offset = startOffset + recordLength;
  return { type: "Metadata", metadata, name };
}
function parseMetadataIndex(reader, recordLength) {
  const startOffset = reader.offset;
  const offset = reader.uint64();
  const length = reader.uint64();
  const name = reader.string();
  reader.offset = startOffset + recordLength;
  return {
    type: "MetadataIndex",
    offset,
    length,
    name
  };
}
function parseSummaryOffset(reader, recordLength) {
  const startOffset = reader.offset;
  const groupOpcode = reader.uint8();
  const groupStart = reader.uint64();
  const groupLength = reader.uint64();
  reader.offset = startOffset + recordLength;
  return {
    type: "SummaryOffset",
    groupOpcode,
    groupStart,
    groupLength
  };
}
function parseDataEnd(reader, recordLength) {
  const startOffset = reader.offset;
  const dataSectionCrc = reader.uint32();
  reader.offset = startOffset + recordLength;
  return {
    type: "DataEnd",
    dataSectionCrc
  };
}

// node_modules/@mcap/core/dist/esm/McapStreamReader.js
var import_crc3 = __toESM(require_src(), 1);
var McapStreamReader = class {
  #buffer = new ArrayBuffer(MCAP_MAGIC.length * 2);
  #view = new DataView(this.#buffer, 0, 0);
  #reader = new Reader(this.#view);
  #decompressHandlers;
  #includeChunks;
  #validateCrcs;
  #noMagicPrefix;
  #doneReading = false;
  #generator = this.#read();
  #channelsById = /* @__PURE__ */ new Map();
  constructor({ includeChunks = false, decompressHandlers: decompressHandlers2 = {}, validateCrcs = true, noMagicPrefix = false } = {}) {
    this.#includeChunks = includeChunks;
    this.#decompressHandlers = decompressHandlers2;
    this.#validateCrcs = validateCrcs;
    this.#noMagicPrefix = noMagicPrefix;
  }
  /** @returns True if a valid, complete mcap file has been parsed. */
  done() {
    return this.#doneReading;
  }
  /** @returns The number of bytes that have been received by `append()` but not yet parsed. */
  bytesRemaining() {
    return this.#reader.bytesRemaining();
  }
  /**
   * Provide the reader with newly received bytes for it to process. After calling this function,
   * call `nextRecord()` again to parse any records that are now available.
   */
  append(data) {
    if (this.#doneReading) {
      throw new Error("Already done reading");
    }
    this.#appendOrShift(data);
  }
  #appendOrShift(data) {
    const consumedBytes = this.#reader.offset;
    const unconsumedBytes = this.#view.byteLength - consumedBytes;
    const neededCapacity = unconsumedBytes + data.byteLength;
    if (neededCapacity <= this.#buffer.byteLength) {
      if (this.#view.byteOffset + this.#view.byteLength + data.byteLength <= this.#buffer.byteLength) {
        const array = new Uint8Array(this.#buffer, this.#view.byteOffset);
        array.set(data, this.#view.byteLength);
        this.#view = new DataView(this.#buffer, this.#view.byteOffset, this.#view.byteLength + data.byteLength);
        this.#reader.reset(this.#view, this.#reader.offset);
      } else {
        const existingData = new Uint8Array(this.#buffer, this.#view.byteOffset + consumedBytes, unconsumedBytes);
        const array = new Uint8Array(this.#buffer);
        array.set(existingData, 0);
        array.set(data, existingData.byteLength);
        this.#view = new DataView(this.#buffer, 0, existingData.byteLength + data.byteLength);
        this.#reader.reset(this.#view);
      }
    } else {
      this.#buffer = new ArrayBuffer(neededCapacity * 2);
      const array = new Uint8Array(this.#buffer);
      const existingData = new Uint8Array(this.#view.buffer, this.#view.byteOffset + consumedBytes, unconsumedBytes);
      array.set(existingData, 0);
      array.set(data, existingData.byteLength);
      this.#view = new DataView(this.#buffer, 0, existingData.byteLength + data.byteLength);
      this.#reader.reset(this.#view);
    }
  }
  /**
   * Read the next record from the stream if possible. If not enough data is available to parse a
   * complete record, or if the reading has terminated with a valid footer, returns undefined.
   *
   * This function may throw any errors encountered during parsing. If an error is thrown, the
   * reader is in an unspecified state and should no longer be used.
   */
  nextRecord() {
    if (this.#doneReading) {
      return void 0;
    }
    const result = this.#generator.next();
    if (result.value?.type === "Channel") {
      const existing = this.#channelsById.get(result.value.id);
      this.#channelsById.set(result.value.id, result.value);
      if (existing && !isChannelEqual(existing, result.value)) {
        throw new Error(`Channel record for id ${result.value.id} (topic: ${result.value.topic}) differs from previous channel record of the same id.`);
      }
    } else if (result.value?.type === "Message") {
      const channelId = result.value.channelId;
      const existing = this.#channelsById.get(channelId);
      if (!existing) {
        throw new Error(`Encountered message on channel ${channelId} without prior channel record`);
      }
    }
    if (result.done === true) {
      this.#doneReading = true;
    }
    return result.value;
  }
  *#read() {
    if (!this.#noMagicPrefix) {
      let magic;
      while (magic = parseMagic(this.#reader), !magic) {
        yield;
      }
    }
    let header;
    function errorWithLibrary(message) {
      return new Error(`${message} ${header ? `[library=${header.library}]` : "[no header]"}`);
    }
    for (; ; ) {
      let record;
      while (record = parseRecord(this.#reader, this.#validateCrcs), !record) {
        yield;
      }
      switch (record.type) {
        case "Header":
          if (header) {
            throw new Error(`Duplicate Header record: library=${header.library} profile=${header.profile} vs. library=${record.library} profile=${record.profile}`);
          }
          header = record;
          yield record;
          break;
        case "Unknown":
        case "Schema":
        case "Channel":
        case "Message":
        case "MessageIndex":
        case "ChunkIndex":
        case "Attachment":
        case "AttachmentIndex":
        case "Statistics":
        case "Metadata":
        case "MetadataIndex":
        case "SummaryOffset":
        case "DataEnd":
          yield record;
          break;
        case "Chunk": {
          if (this.#includeChunks) {
            yield record;
          }
          let buffer = record.records;
          if (record.compression !== "" && buffer.byteLength > 0) {
            const decompress2 = this.#decompressHandlers[record.compression];
            if (!decompress2) {
              throw errorWithLibrary(`Unsupported compression ${record.compression}`);
            }
            buffer = decompress2(buffer, record.uncompressedSize);
          }
          if (this.#validateCrcs && record.uncompressedCrc !== 0) {
            const chunkCrc = (0, import_crc3.crc32)(buffer);
            if (chunkCrc !== record.uncompressedCrc) {
              throw errorWithLibrary(`Incorrect chunk CRC ${chunkCrc} (expected ${record.uncompressedCrc})`);
            }
          }
          const view = new DataView(buffer.buffer, buffer.byteOffset, buffer.byteLength);
          const chunkReader = new Reader(view);
          let chunkRecord;
          while (chunkRecord = parseRecord(chunkReader, this.#validateCrcs)) {
            switch (chunkRecord.type) {
              case "Header":
              case "Footer":
              case "Chunk":
              case "MessageIndex":
              case "ChunkIndex":
              case "Attachment":
              case "AttachmentIndex":
              case "Statistics":
              case "Metadata":
              case "MetadataIndex":
              case "SummaryOffset":
              case "DataEnd":
                throw errorWithLibrary(`${chunkRecord.type} record not allowed inside a chunk`);
              case "Unknown":
              case "Schema":
              case "Channel":
              case "Message":
                yield chunkRecord;
                break;
            }
          }
          if (chunkReader.bytesRemaining() !== 0) {
            throw errorWithLibrary(`${chunkReader.bytesRemaining()} bytes remaining in chunk`);
          }
          break;
        }
        case "Footer":
          try {
            let magic;
            while (magic = parseMagic(this.#reader), !magic) {
              yield;
            }
          } catch (error) {
            throw errorWithLibrary(error.message);
          }
          if (this.#reader.bytesRemaining() !== 0) {
            throw errorWithLibrary(`${this.#reader.bytesRemaining()} bytes remaining after MCAP footer and trailing magic`);
          }
          return record;
      }
    }
  }
};
function isChannelEqual(a, b) {
  if (!(a.id === b.id && a.messageEncoding === b.messageEncoding && a.schemaId === b.schemaId && a.topic === b.topic && a.metadata.size === b.metadata.size)) {
    return false;
  }
  for (const [keyA, valueA] of a.metadata.entries()) {
    const valueB = b.metadata.get(keyA);
    if (valueA !== valueB) {
      return false;
    }
  }
  return true;
}

// node_modules/@mcap/core/dist/esm/McapWriter.js
var import_crc5 = __toESM(require_src(), 1);

// node_modules/@mcap/core/dist/esm/McapRecordBuilder.js
var import_crc4 = __toESM(require_src(), 1);

// node_modules/@mcap/core/dist/esm/version.js
var VERSION = "2.2.2";
var LIBRARY_IDENTIFIER = `mcap-typescript/${VERSION}`;

// node_modules/fzstd/esm/index.mjs
var ab = ArrayBuffer;
var u8 = Uint8Array;
var u16 = Uint16Array;
var i16 = Int16Array;
var i32 = Int32Array;
var slc = function(v, s, e) {
  if (u8.prototype.slice)
    return u8.prototype.slice.call(v, s, e);
  if (s == null || s < 0)
    s = 0;
  if (e == null || e > v.length)
    e = v.length;
  var n = new u8(e - s);
  n.set(v.subarray(s, e));
  return n;
};
var fill = function(v, n, s, e) {
  if (u8.prototype.fill)
    return u8.prototype.fill.call(v, n, s, e);
  if (s == null || s < 0)
    s = 0;
  if (e == null || e > v.length)
    e = v.length;
  for (; s < e; ++s)
    v[s] = n;
  return v;
};
var cpw = function(v, t, s, e) {
  if (u8.prototype.copyWithin)
    return u8.prototype.copyWithin.call(v, t, s, e);
  if (s == null || s < 0)
    s = 0;
  if (e == null || e > v.length)
    e = v.length;
  while (s < e) {
    v[t++] = v[s++];
  }
};
var ec = [
  "invalid zstd data",
  "window size too large (>2046MB)",
  "invalid block type",
  "FSE accuracy too high",
  "match distance too far back",
  "unexpected EOF"
];
var err = function(ind, msg, nt) {
  var e = new Error(msg || ec[ind]);
  e.code = ind;
  if (Error.captureStackTrace)
    Error.captureStackTrace(e, err);
  if (!nt)
    throw e;
  return e;
};
var rb = function(d, b, n) {
  var i = 0, o = 0;
  for (; i < n; ++i)
    o |= d[b++] << (i << 3);
  return o;
};
var b4 = function(d, b) {
  return (d[b] | d[b + 1] << 8 | d[b + 2] << 16 | d[b + 3] << 24) >>> 0;
};
var rzfh = function(dat, w) {
  var n3 = dat[0] | dat[1] << 8 | dat[2] << 16;
  if (n3 == 3126568 && dat[3] == 253) {
    var flg = dat[4];
    var ss = flg >> 5 & 1, cc = flg >> 2 & 1, df = flg & 3, fcf = flg >> 6;
    if (flg & 8)
      err(0);
    var bt = 6 - ss;
    var db = df == 3 ? 4 : df;
    var di = rb(dat, bt, db);
    bt += db;
    var fsb = fcf ? 1 << fcf : ss;
    var fss = rb(dat, bt, fsb) + (fcf == 1 && 256);
    var ws = fss;
    if (!ss) {
      var wb = 1 << 10 + (dat[5] >> 3);
      ws = wb + (wb >> 3) * (dat[5] & 7);
    }
    if (ws > 2145386496)
      err(1);
    var buf = new u8((w == 1 ? fss || ws : w ? 0 : ws) + 12);
    buf[0] = 1, buf[4] = 4, buf[8] = 8;
    return {
      b: bt + fsb,
      y: 0,
      l: 0,
      d: di,
      w: w && w != 1 ? w : buf.subarray(12),
      e: ws,
      o: new i32(buf.buffer, 0, 3),
      u: fss,
      c: cc,
      m: Math.min(131072, ws)
    };
  } else if ((n3 >> 4 | dat[3] << 20) == 25481893) {
    return b4(dat, 4) + 8;
  }
  err(0);
};
var msb = function(val) {
  var bits = 0;
  for (; 1 << bits <= val; ++bits)
    ;
  return bits - 1;
};
var rfse = function(dat, bt, mal) {
  var tpos = (bt << 3) + 4;
  var al = (dat[bt] & 15) + 5;
  if (al > mal)
    err(3);
  var sz = 1 << al;
  var probs = sz, sym = -1, re = -1, i = -1, ht = sz;
  var buf = new ab(512 + (sz << 2));
  var freq = new i16(buf, 0, 256);
  var dstate = new u16(buf, 0, 256);
  var nstate = new u16(buf, 512, sz);
  var bb1 = 512 + (sz << 1);
  var syms = new u8(buf, bb1, sz);
  var nbits = new u8(buf, bb1 + sz);
  while (sym < 255 && probs > 0) {
    var bits = msb(probs + 1);
    var cbt = tpos >> 3;
    var msk = (1 << bits + 1) - 1;
    var val = (dat[cbt] | dat[cbt + 1] << 8 | dat[cbt + 2] << 16) >> (tpos & 7) & msk;
    var msk1fb = (1 << bits) - 1;
    var msv = msk - probs - 1;
    var sval = val & msk1fb;
    if (sval < msv)
      tpos += bits, val = sval;
    else {
      tpos += bits + 1;
      if (val > msk1fb)
        val -= msv;
    }
    freq[++sym] = --val;
    if (val == -1) {
      probs += val;
      syms[--ht] = sym;
    } else
      probs -= val;
    if (!val) {
      do {
        var rbt = tpos >> 3;
        re = (dat[rbt] | dat[rbt + 1] << 8) >> (tpos & 7) & 3;
        tpos += 2;
        sym += re;
      } while (re == 3);
    }
  }
  if (sym > 255 || probs)
    err(0);
  var sympos = 0;
  var sstep = (sz >> 1) + (sz >> 3) + 3;
  var smask = sz - 1;
  for (var s = 0; s <= sym; ++s) {
    var sf = freq[s];
    if (sf < 1) {
      dstate[s] = -sf;
      continue;
    }
    for (i = 0; i < sf; ++i) {
      syms[sympos] = s;
      do {
        sympos = sympos + sstep & smask;
      } while (sympos >= ht);
    }
  }
  if (sympos)
    err(0);
  for (i = 0; i < sz; ++i) {
    var ns = dstate[syms[i]]++;
    var nb = nbits[i] = al - msb(ns);
    nstate[i] = (ns << nb) - sz;
  }
  return [tpos + 7 >> 3, {
    b: al,
    s: syms,
    n: nbits,
    t: nstate
  }];
};
var rhu = function(dat, bt) {
  var i = 0, wc = -1;
  var buf = new u8(292), hb = dat[bt];
  var hw = buf.subarray(0, 256);
  var rc = buf.subarray(256, 268);
  var ri = new u16(buf.buffer, 268);
  if (hb < 128) {
    var _a = rfse(dat, bt + 1, 6), ebt = _a[0], fdt = _a[1];
    bt += hb;
    var epos = ebt << 3;
    var lb = dat[bt];
    if (!lb)
      err(0);
    var st1 = 0, st2 = 0, btr1 = fdt.b, btr2 = btr1;
    var fpos = (++bt << 3) - 8 + msb(lb);
    for (; ; ) {
      fpos -= btr1;
      if (fpos < epos)
        break;
      var cbt = fpos >> 3;
      st1 += (dat[cbt] | dat[cbt + 1] << 8) >> (fpos & 7) & (1 << btr1) - 1;
      hw[++wc] = fdt.s[st1];
      fpos -= btr2;
      if (fpos < epos)
        break;
      cbt = fpos >> 3;
      st2 += (dat[cbt] | dat[cbt + 1] << 8) >> (fpos & 7) & (1 << btr2) - 1;
      hw[++wc] = fdt.s[st2];
      btr1 = fdt.n[st1];
      st1 = fdt.t[st1];
      btr2 = fdt.n[st2];
      st2 = fdt.t[st2];
    }
    if (++wc > 255)
      err(0);
  } else {
    wc = hb - 127;
    for (; i < wc; i += 2) {
      var byte = dat[++bt];
      hw[i] = byte >> 4;
      hw[i + 1] = byte & 15;
    }
    ++bt;
  }
  var wes = 0;
  for (i = 0; i < wc; ++i) {
    var wt = hw[i];
    if (wt > 11)
      err(0);
    wes += wt && 1 << wt - 1;
  }
  var mb = msb(wes) + 1;
  var ts = 1 << mb;
  var rem = ts - wes;
  if (rem & rem - 1)
    err(0);
  hw[wc++] = msb(rem) + 1;
  for (i = 0; i < wc; ++i) {
    var wt = hw[i];
    ++rc[hw[i] = wt && mb + 1 - wt];
  }
  var hbuf = new u8(ts << 1);
  var syms = hbuf.subarray(0, ts), nb = hbuf.subarray(ts);
  ri[mb] = 0;
  for (i = mb; i > 0; --i) {
    var pv = ri[i];
    fill(nb, i, pv, ri[i - 1] = pv + rc[i] * (1 << mb - i));
  }
  if (ri[0] != ts)
    err(0);
  for (i = 0; i < wc; ++i) {
    var bits = hw[i];
    if (bits) {
      var code = ri[bits];
      fill(syms, i, code, ri[bits] = code + (1 << mb - bits));
    }
  }
  return [bt, {
    n: nb,
    b: mb,
    s: syms
  }];
};
var dllt = rfse(/* @__PURE__ */ new u8([
  81,
  16,
  99,
  140,
  49,
  198,
  24,
  99,
  12,
  33,
  196,
  24,
  99,
  102,
  102,
  134,
  70,
  146,
  4
]), 0, 6)[1];
var dmlt = rfse(/* @__PURE__ */ new u8([
  33,
  20,
  196,
  24,
  99,
  140,
  33,
  132,
  16,
  66,
  8,
  33,
  132,
  16,
  66,
  8,
  33,
  68,
  68,
  68,
  68,
  68,
  68,
  68,
  68,
  36,
  9
]), 0, 6)[1];
var doct = rfse(/* @__PURE__ */ new u8([
  32,
  132,
  16,
  66,
  102,
  70,
  68,
  68,
  68,
  68,
  36,
  73,
  2
]), 0, 5)[1];
var b2bl = function(b, s) {
  var len = b.length, bl = new i32(len);
  for (var i = 0; i < len; ++i) {
    bl[i] = s;
    s += 1 << b[i];
  }
  return bl;
};
var llb = /* @__PURE__ */ new u8((/* @__PURE__ */ new i32([
  0,
  0,
  0,
  0,
  16843009,
  50528770,
  134678020,
  202050057,
  269422093
])).buffer, 0, 36);
var llbl = /* @__PURE__ */ b2bl(llb, 0);
var mlb = /* @__PURE__ */ new u8((/* @__PURE__ */ new i32([
  0,
  0,
  0,
  0,
  0,
  0,
  0,
  0,
  16843009,
  50528770,
  117769220,
  185207048,
  252579084,
  16
])).buffer, 0, 53);
var mlbl = /* @__PURE__ */ b2bl(mlb, 3);
var dhu = function(dat, out, hu) {
  var len = dat.length, ss = out.length, lb = dat[len - 1], msk = (1 << hu.b) - 1, eb = -hu.b;
  if (!lb)
    err(0);
  var st = 0, btr = hu.b, pos = (len << 3) - 8 + msb(lb) - btr, i = -1;
  for (; pos > eb && i < ss; ) {
    var cbt = pos >> 3;
    var val = (dat[cbt] | dat[cbt + 1] << 8 | dat[cbt + 2] << 16) >> (pos & 7);
    st = (st << btr | val) & msk;
    out[++i] = hu.s[st];
    pos -= btr = hu.n[st];
  }
  if (pos != eb || i + 1 != ss)
    err(0);
};
var dhu4 = function(dat, out, hu) {
  var bt = 6;
  var ss = out.length, sz1 = ss + 3 >> 2, sz2 = sz1 << 1, sz3 = sz1 + sz2;
  dhu(dat.subarray(bt, bt += dat[0] | dat[1] << 8), out.subarray(0, sz1), hu);
  dhu(dat.subarray(bt, bt += dat[2] | dat[3] << 8), out.subarray(sz1, sz2), hu);
  dhu(dat.subarray(bt, bt += dat[4] | dat[5] << 8), out.subarray(sz2, sz3), hu);
  dhu(dat.subarray(bt), out.subarray(sz3), hu);
};
var rzb = function(dat, st, out) {
  var _a;
  var bt = st.b;
  var b0 = dat[bt], btype = b0 >> 1 & 3;
  st.l = b0 & 1;
  var sz = b0 >> 3 | dat[bt + 1] << 5 | dat[bt + 2] << 13;
  var ebt = (bt += 3) + sz;
  if (btype == 1) {
    if (bt >= dat.length)
      return;
    st.b = bt + 1;
    if (out) {
      fill(out, dat[bt], st.y, st.y += sz);
      return out;
    }
    return fill(new u8(sz), dat[bt]);
  }
  if (ebt > dat.length)
    return;
  if (btype == 0) {
    st.b = ebt;
    if (out) {
      out.set(dat.subarray(bt, ebt), st.y);
      st.y += sz;
      return out;
    }
    return slc(dat, bt, ebt);
  }
  if (btype == 2) {
    var b3 = dat[bt], lbt = b3 & 3, sf = b3 >> 2 & 3;
    var lss = b3 >> 4, lcs = 0, s4 = 0;
    if (lbt < 2) {
      if (sf & 1)
        lss |= dat[++bt] << 4 | (sf & 2 && dat[++bt] << 12);
      else
        lss = b3 >> 3;
    } else {
      s4 = sf;
      if (sf < 2)
        lss |= (dat[++bt] & 63) << 4, lcs = dat[bt] >> 6 | dat[++bt] << 2;
      else if (sf == 2)
        lss |= dat[++bt] << 4 | (dat[++bt] & 3) << 12, lcs = dat[bt] >> 2 | dat[++bt] << 6;
      else
        lss |= dat[++bt] << 4 | (dat[++bt] & 63) << 12, lcs = dat[bt] >> 6 | dat[++bt] << 2 | dat[++bt] << 10;
    }
    ++bt;
    var buf = out ? out.subarray(st.y, st.y + st.m) : new u8(st.m);
    var spl = buf.length - lss;
    if (lbt == 0)
      buf.set(dat.subarray(bt, bt += lss), spl);
    else if (lbt == 1)
      fill(buf, dat[bt++], spl);
    else {
      var hu = st.h;
      if (lbt == 2) {
        var hud = rhu(dat, bt);
        lcs += bt - (bt = hud[0]);
        st.h = hu = hud[1];
      } else if (!hu)
        err(0);
      (s4 ? dhu4 : dhu)(dat.subarray(bt, bt += lcs), buf.subarray(spl), hu);
    }
    var ns = dat[bt++];
    if (ns) {
      if (ns == 255)
        ns = (dat[bt++] | dat[bt++] << 8) + 32512;
      else if (ns > 127)
        ns = ns - 128 << 8 | dat[bt++];
      var scm = dat[bt++];
      if (scm & 3)
        err(0);
      var dts = [dmlt, doct, dllt];
      for (var i = 2; i > -1; --i) {
        var md = scm >> (i << 1) + 2 & 3;
        if (md == 1) {
          var rbuf = new u8([0, 0, dat[bt++]]);
          dts[i] = {
            s: rbuf.subarray(2, 3),
            n: rbuf.subarray(0, 1),
            t: new u16(rbuf.buffer, 0, 1),
            b: 0
          };
        } else if (md == 2) {
          _a = rfse(dat, bt, 9 - (i & 1)), bt = _a[0], dts[i] = _a[1];
        } else if (md == 3) {
          if (!st.t)
            err(0);
          dts[i] = st.t[i];
        }
      }
      var _b = st.t = dts, mlt = _b[0], oct = _b[1], llt = _b[2];
      var lb = dat[ebt - 1];
      if (!lb)
        err(0);
      var spos = (ebt << 3) - 8 + msb(lb) - llt.b, cbt = spos >> 3, oubt = 0;
      var lst = (dat[cbt] | dat[cbt + 1] << 8) >> (spos & 7) & (1 << llt.b) - 1;
      cbt = (spos -= oct.b) >> 3;
      var ost = (dat[cbt] | dat[cbt + 1] << 8) >> (spos & 7) & (1 << oct.b) - 1;
      cbt = (spos -= mlt.b) >> 3;
      var mst = (dat[cbt] | dat[cbt + 1] << 8) >> (spos & 7) & (1 << mlt.b) - 1;
      for (++ns; --ns; ) {
        var llc = llt.s[lst];
        var lbtr = llt.n[lst];
        var mlc = mlt.s[mst];
        var mbtr = mlt.n[mst];
        var ofc = oct.s[ost];
        var obtr = oct.n[ost];
        cbt = (spos -= ofc) >> 3;
        var ofp = 1 << ofc;
        var off = ofp + ((dat[cbt] | dat[cbt + 1] << 8 | dat[cbt + 2] << 16 | dat[cbt + 3] << 24) >>> (spos & 7) & ofp - 1);
        cbt = (spos -= mlb[mlc]) >> 3;
        var ml = mlbl[mlc] + ((dat[cbt] | dat[cbt + 1] << 8 | dat[cbt + 2] << 16) >> (spos & 7) & (1 << mlb[mlc]) - 1);
        cbt = (spos -= llb[llc]) >> 3;
        var ll = llbl[llc] + ((dat[cbt] | dat[cbt + 1] << 8 | dat[cbt + 2] << 16) >> (spos & 7) & (1 << llb[llc]) - 1);
        cbt = (spos -= lbtr) >> 3;
        lst = llt.t[lst] + ((dat[cbt] | dat[cbt + 1] << 8) >> (spos & 7) & (1 << lbtr) - 1);
        cbt = (spos -= mbtr) >> 3;
        mst = mlt.t[mst] + ((dat[cbt] | dat[cbt + 1] << 8) >> (spos & 7) & (1 << mbtr) - 1);
        cbt = (spos -= obtr) >> 3;
        ost = oct.t[ost] + ((dat[cbt] | dat[cbt + 1] << 8) >> (spos & 7) & (1 << obtr) - 1);
        if (off > 3) {
          st.o[2] = st.o[1];
          st.o[1] = st.o[0];
          st.o[0] = off -= 3;
        } else {
          var idx = off - (ll != 0);
          if (idx) {
            off = idx == 3 ? st.o[0] - 1 : st.o[idx];
            if (idx > 1)
              st.o[2] = st.o[1];
            st.o[1] = st.o[0];
            st.o[0] = off;
          } else
            off = st.o[0];
        }
        for (var i = 0; i < ll; ++i) {
          buf[oubt + i] = buf[spl + i];
        }
        oubt += ll, spl += ll;
        var stin = oubt - off;
        if (stin < 0) {
          var len = -stin;
          var bs = st.e + stin;
          if (len > ml)
            len = ml;
          for (var i = 0; i < len; ++i) {
            buf[oubt + i] = st.w[bs + i];
          }
          oubt += len, ml -= len, stin = 0;
        }
        for (var i = 0; i < ml; ++i) {
          buf[oubt + i] = buf[stin + i];
        }
        oubt += ml;
      }
      if (oubt != spl) {
        while (spl < buf.length) {
          buf[oubt++] = buf[spl++];
        }
      } else
        oubt = buf.length;
      if (out)
        st.y += oubt;
      else
        buf = slc(buf, 0, oubt);
    } else if (out) {
      st.y += lss;
      if (spl) {
        for (var i = 0; i < lss; ++i) {
          buf[i] = buf[spl + i];
        }
      }
    } else if (spl)
      buf = slc(buf, spl);
    st.b = ebt;
    return buf;
  }
  err(2);
};
var cct = function(bufs, ol) {
  if (bufs.length == 1)
    return bufs[0];
  var buf = new u8(ol);
  for (var i = 0, b = 0; i < bufs.length; ++i) {
    var chk = bufs[i];
    buf.set(chk, b);
    b += chk.length;
  }
  return buf;
};
function decompress(dat, buf) {
  var bufs = [], nb = +!buf;
  var bt = 0, ol = 0;
  for (; dat.length; ) {
    var st = rzfh(dat, nb || buf);
    if (typeof st == "object") {
      if (nb) {
        buf = null;
        if (st.w.length == st.u) {
          bufs.push(buf = st.w);
          ol += st.u;
        }
      } else {
        bufs.push(buf);
        st.e = 0;
      }
      for (; !st.l; ) {
        var blk = rzb(dat, st, buf);
        if (!blk)
          err(5);
        if (buf)
          st.e = st.y;
        else {
          bufs.push(blk);
          ol += blk.length;
          cpw(st.w, 0, blk.length);
          st.w.set(blk, st.w.length - blk.length);
        }
      }
      bt = st.b + st.c * 4;
    } else
      bt = st;
    dat = dat.subarray(bt);
  }
  return cct(bufs, ol);
}

// build/parseChannel.mjs
var import_base64 = __toESM(require_base64(), 1);
function notCopied(encoding) {
  return () => {
    throw new Error(`the ${encoding} parser is not bundled (this runner checks JSON channels)`);
  };
}
var parseFlatbufferSchema = notCopied("flatbuffer");
var descriptor = { FileDescriptorSet: { decode: notCopied("protobuf") } };
var protobufjs_default = notCopied("protobuf");
var protobufDefinitionsToDatatypes = notCopied("protobuf");
var stripLeadingDot = notCopied("protobuf");
var rosmsg_dist = { parse: notCopied("ros1msg/ros2msg"), parseRos2idl: notCopied("ros2idl") };
var dist_esm = { MessageReader: notCopied("ros1") };
var rosmsg2_serialization_dist = { MessageReader: notCopied("cdr") };
function parseJsonSchema(rootJsonSchema, rootTypeName) {
  const datatypes = /* @__PURE__ */ new Map();
  function addFieldsRecursive(schema, typeName, keyPath) {
    let postprocessObject = (value) => value;
    const fields = [];
    if (schema.type !== "object") {
      throw new Error(`Expected "type": "object" for schema ${typeName}, got ${JSON.stringify(schema.type)}`);
    }
    for (const [fieldName, fieldSchema] of Object.entries(schema.properties)) {
      if (Array.isArray(fieldSchema.oneOf)) {
        if (fieldSchema.oneOf.every((alternative) => typeof alternative.const === "number")) {
          for (const alternative of fieldSchema.oneOf) {
            fields.push({
              name: alternative.title,
              type: "uint32",
              isConstant: true,
              value: alternative.const
            });
          }
          fields.push({ name: fieldName, type: "uint32" });
          continue;
        } else {
          throw new Error(`Unsupported type for ${keyPath.concat(fieldName).join(".")}: oneOf alternatives must have number values`);
        }
      }
      switch (fieldSchema.type) {
        case "boolean":
          fields.push({ name: fieldName, type: "bool" });
          break;
        case "string":
          switch (fieldSchema.contentEncoding) {
            case void 0:
              fields.push({ name: fieldName, type: "string" });
              break;
            case "base64": {
              fields.push({ name: fieldName, type: "uint8", isArray: true });
              const prevPostprocess = postprocessObject;
              postprocessObject = (value) => {
                const str = value[fieldName];
                if (typeof str === "string") {
                  const decoded = new Uint8Array(import_base64.default.length(str));
                  if (import_base64.default.decode(str, decoded, 0) !== decoded.byteLength) {
                    throw new Error(`Failed to decode base64 data for ${keyPath.concat(fieldName).join(".")}`);
                  }
                  value[fieldName] = decoded;
                }
                return prevPostprocess(value);
              };
              break;
            }
            default:
              throw new Error(`Unsupported contentEncoding ${JSON.stringify(fieldSchema.contentEncoding)} in ${keyPath.concat(fieldName).join(".")}`);
          }
          break;
        case "number":
        case "integer":
          fields.push({ name: fieldName, type: "float64" });
          break;
        case "object": {
          const nestedTypeName = `${typeName}.${fieldName}`;
          const postprocessNestedObject = addFieldsRecursive(fieldSchema, nestedTypeName, keyPath.concat(fieldName));
          const prevPostprocess = postprocessObject;
          postprocessObject = (value) => {
            const fieldValue = value[fieldName];
            if (fieldValue != void 0 && typeof fieldValue === "object") {
              value[fieldName] = postprocessNestedObject(fieldValue);
            }
            return prevPostprocess(value);
          };
          fields.push({ name: fieldName, type: nestedTypeName, isComplex: true });
          break;
        }
        case "array": {
          const itemSchema = fieldSchema.items;
          switch (itemSchema.type) {
            case "boolean":
              fields.push({ name: fieldName, type: "bool", isArray: true });
              break;
            case "string":
              if (itemSchema.contentEncoding != void 0) {
                throw new Error(`Unsupported contentEncoding ${JSON.stringify(itemSchema.contentEncoding)} for array item ${keyPath.concat(fieldName).join(".")}`);
              }
              fields.push({ name: fieldName, type: "string", isArray: true });
              break;
            case "number":
            case "integer":
              fields.push({ name: fieldName, type: "float64", isArray: true });
              break;
            case "object": {
              const nestedTypeName = `${typeName}.${fieldName}`;
              const postprocessArrayItem = addFieldsRecursive(fieldSchema.items, nestedTypeName, keyPath.concat(fieldName));
              const prevPostprocess = postprocessObject;
              postprocessObject = (value) => {
                const arr = value[fieldName];
                if (Array.isArray(arr)) {
                  value[fieldName] = arr.map(postprocessArrayItem);
                }
                return prevPostprocess(value);
              };
              fields.push({
                name: fieldName,
                type: nestedTypeName,
                isComplex: true,
                isArray: true
              });
              break;
            }
            default:
              throw new Error(`Unsupported type ${JSON.stringify(itemSchema.type)} for array item ${keyPath.concat(fieldName).join(".")}`);
          }
          break;
        }
        case "null":
        default:
          throw new Error(`Unsupported type ${JSON.stringify(fieldSchema.type)} for ${keyPath.concat(fieldName).join(".")}`);
      }
    }
    datatypes.set(typeName, { definitions: fields });
    return postprocessObject;
  }
  const postprocessValue = addFieldsRecursive(rootJsonSchema, rootTypeName, []);
  return { datatypes, postprocessValue };
}
function parsedDefinitionsToDatatypes(parsedDefinitions, rootName) {
  const datatypes = /* @__PURE__ */ new Map();
  parsedDefinitions.forEach(({ name, definitions }, index) => {
    if (index === 0) {
      datatypes.set(rootName, { name: rootName, definitions });
    } else if (name != void 0) {
      datatypes.set(name, { name, definitions });
    }
  });
  return datatypes;
}
function parseChannel2(channel) {
  if (channel.messageEncoding === "json") {
    if (channel.schema != void 0 && channel.schema.encoding !== "jsonschema") {
      throw new Error(`Message encoding ${channel.messageEncoding} with schema encoding '${channel.schema.encoding}' is not supported (expected jsonschema or no schema)`);
    }
    const textDecoder2 = new TextDecoder();
    let datatypes = /* @__PURE__ */ new Map();
    let deserialize = (data) => JSON.parse(textDecoder2.decode(data));
    if (channel.schema != void 0) {
      const schema = channel.schema.data.length > 0 ? JSON.parse(textDecoder2.decode(channel.schema.data)) : void 0;
      if (schema != void 0) {
        if (typeof schema !== "object") {
          throw new Error(`Invalid schema, expected JSON object, got ${typeof schema}`);
        }
        const { datatypes: parsedDatatypes, postprocessValue } = parseJsonSchema(schema, channel.schema.name);
        datatypes = parsedDatatypes;
        deserialize = (data) => postprocessValue(JSON.parse(textDecoder2.decode(data)));
      }
    }
    return { deserialize, datatypes };
  }
  if (channel.messageEncoding === "flatbuffer") {
    if (channel.schema?.encoding !== "flatbuffer") {
      throw new Error(`Message encoding ${channel.messageEncoding} with ${channel.schema == void 0 ? "no encoding" : `schema encoding '${channel.schema.encoding}'`} is not supported (expected flatbuffer)`);
    }
    return parseFlatbufferSchema(channel.schema.name, channel.schema.data);
  }
  if (channel.messageEncoding === "protobuf") {
    if (channel.schema?.encoding !== "protobuf") {
      throw new Error(`Message encoding ${channel.messageEncoding} with ${channel.schema == void 0 ? "no encoding" : `schema encoding '${channel.schema.encoding}'`} is not supported (expected protobuf)`);
    }
    const descriptorSet = descriptor.FileDescriptorSet.decode(channel.schema.data);
    for (const file of descriptorSet.file) {
      if (file.package === "google.protobuf") {
        for (const message of file.messageType ?? []) {
          if (message.name === "Timestamp" || message.name === "Duration") {
            for (const field of message.field ?? []) {
              if (field.name === "seconds") {
                field.name = "sec";
              } else if (field.name === "nanos") {
                field.name = "nsec";
              }
            }
          }
        }
      }
    }
    const root = protobufjs_default().Root.fromDescriptor(descriptorSet);
    root.resolveAll();
    const type = root.lookupType(channel.schema.name);
    const deserialize = (data) => {
      return type.toObject(type.decode(new Uint8Array(data.buffer, data.byteOffset, data.byteLength)), { defaults: true });
    };
    const datatypes = /* @__PURE__ */ new Map();
    protobufDefinitionsToDatatypes(datatypes, type);
    if (!datatypes.has(channel.schema.name)) {
      throw new Error(`Protobuf schema does not contain an entry for '${channel.schema.name}'. The schema name should be fully-qualified, e.g. '${stripLeadingDot(type.fullName)}'.`);
    }
    return { deserialize, datatypes };
  }
  if (channel.messageEncoding === "ros1") {
    if (channel.schema?.encoding !== "ros1msg") {
      throw new Error(`Message encoding ${channel.messageEncoding} with ${channel.schema == void 0 ? "no encoding" : `schema encoding '${channel.schema.encoding}'`} is not supported (expected ros1msg)`);
    }
    const schema = new TextDecoder().decode(channel.schema.data);
    const parsedDefinitions = (0, rosmsg_dist.parse)(schema);
    const reader = new dist_esm.MessageReader(parsedDefinitions);
    return {
      datatypes: parsedDefinitionsToDatatypes(parsedDefinitions, channel.schema.name),
      deserialize: (data) => reader.readMessage(data)
    };
  }
  if (channel.messageEncoding === "cdr") {
    if (channel.schema?.encoding !== "ros2msg" && channel.schema?.encoding !== "ros2idl") {
      throw new Error(`Message encoding ${channel.messageEncoding} with ${channel.schema == void 0 ? "no encoding" : `schema encoding '${channel.schema.encoding}'`} is not supported (expected "ros2msg" or "ros2idl")`);
    }
    const schema = new TextDecoder().decode(channel.schema.data);
    const isIdl = channel.schema.encoding === "ros2idl";
    const parsedDefinitions = isIdl ? (0, rosmsg_dist.parseRos2idl)(schema) : (0, rosmsg_dist.parse)(schema, { ros2: true });
    const reader = new rosmsg2_serialization_dist.MessageReader(parsedDefinitions);
    return {
      datatypes: parsedDefinitionsToDatatypes(parsedDefinitions, channel.schema.name),
      deserialize: (data) => reader.readMessage(data)
    };
  }
  throw new Error(`Unsupported encoding ${channel.messageEncoding}`);
}

// check_channels.mjs
var PARSER = "@foxglove/studio-base@1.48.0 parseChannel";
var decompressHandlers = {
  zstd: (buffer, decompressedSize) => decompress(buffer, new Uint8Array(Number(decompressedSize)))
};
function errorText(error) {
  return error instanceof Error ? `${error.name}: ${error.message}` : String(error);
}
function* records(bytes) {
  const reader = new McapStreamReader({ decompressHandlers });
  reader.append(bytes);
  for (let record; record = reader.nextRecord(); ) {
    yield record;
  }
  if (!reader.done()) {
    throw new Error(`the file ends inside a record (${reader.bytesRemaining()} bytes left)`);
  }
}
function checkChannels(path) {
  const schemas = /* @__PURE__ */ new Map();
  const channels = /* @__PURE__ */ new Map();
  for (const record of records(readFileSync(path))) {
    if (record.type === "Schema") {
      schemas.set(record.id, record);
    } else if (record.type === "Channel" && !channels.has(record.id)) {
      const schema = schemas.get(record.schemaId);
      const report = {
        id: record.id,
        topic: record.topic,
        message_encoding: record.messageEncoding,
        schema: schema?.name ?? null,
        schema_encoding: schema?.encoding ?? null,
        ok: true,
        error: null,
        messages: 0,
        failed_messages: 0,
        datatypes: null
      };
      let parsed;
      try {
        parsed = parseChannel2({
          messageEncoding: record.messageEncoding,
          schema: schema == void 0 ? void 0 : { name: schema.name, encoding: schema.encoding, data: schema.data }
        });
        report.datatypes = Object.fromEntries(parsed.datatypes);
      } catch (error) {
        report.ok = false;
        report.error = errorText(error);
      }
      channels.set(record.id, { report, parsed });
    } else if (record.type === "Message") {
      const channel = channels.get(record.channelId);
      if (channel?.parsed == void 0) {
        continue;
      }
      try {
        channel.parsed.deserialize(record.data);
        channel.report.messages += 1;
      } catch (error) {
        channel.report.failed_messages += 1;
        if (channel.report.ok) {
          channel.report.ok = false;
          channel.report.error = `message at log_time ${record.logTime}: ${errorText(error)}`;
        }
      }
    }
  }
  return { file: path, parser: PARSER, channels: [...channels.values()].map((c) => c.report) };
}
var paths = process.argv.slice(2);
if (paths.length !== 1) {
  console.error("usage: node check_channels.mjs RECORDING.mcap");
  process.exit(2);
}
try {
  console.log(JSON.stringify(checkChannels(paths[0])));
} catch (error) {
  console.error(`${paths[0]}: ${errorText(error)}`);
  process.exit(2);
}
