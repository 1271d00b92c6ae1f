MODULE FixedWobj
    PERS wobjdata wobjTable := [FALSE, TRUE, "", [[250, -100, 100], [1, 0, 0, 0]], [[0, 0, 0], [1, 0, 0, 0]]];
    CONST robtarget pCorner := [[0, 0, 150], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pFar := [[100, 200, 150], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    PROC main()
        MoveJ pCorner, v1000, z20, tool0 \WObj:=wobjTable;
        MoveL pFar, v500, fine, tool0 \WObj:=wobjTable;
        MoveL RelTool(pFar, 0, 0, -50), v200, fine, tool0 \WObj:=wobjTable;
    ENDPROC
ENDMODULE
